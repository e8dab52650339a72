#!/bin/sh
# lucent with its BVH kernels limited to AVX2, as on a CPU without AVX-512 (`--isa avx2`
# added to every command). Give it to ../shared/bench/compare4.sh in place of the binary,
# with Embree limited the same way:
#   EB_CONFIG=max_isa=avx2 ../shared/bench/compare4.sh scripts/lucent_avx2.sh MESH ...
# LUCENT picks the binary (default: target/release/lucent of this checkout). exec keeps the
# process id, which compare4.sh's CPU-time wrapper reads.
here=$(cd "$(dirname "$0")/.." && pwd)
exec "${LUCENT:-$here/target/release/lucent}" "$@" --isa avx2
