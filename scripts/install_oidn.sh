#!/bin/sh
# Installs Intel Open Image Denoise for `lucent render --denoise`: downloads the pyoidn
# wheel from PyPI (it ships libOpenImageDenoise.so and its own dependencies) and unpacks
# it into $XDG_DATA_HOME/lucent/oidn (default ~/.local/share/lucent/oidn), where lucent
# looks for the library. Nothing is installed system-wide; remove that folder to undo.
# Usage: scripts/install_oidn.sh [--force]
set -eu
data="${XDG_DATA_HOME:-$HOME/.local/share}"
dest="$data/lucent/oidn"
lib="$dest/pyoidn/oidn/lib/libOpenImageDenoise.so.2"
if [ -e "$lib" ] && [ "${1:-}" != "--force" ]; then
    echo "install_oidn: Open Image Denoise is already installed: $lib"
    exit 0
fi
command -v python3 >/dev/null || { echo "install_oidn: python3 is needed to fetch the wheel" >&2; exit 1; }
if ! python3 -m pip --version >/dev/null 2>&1; then
    echo "install_oidn: pip is missing; installing python3-pip with apt-get"
    if [ "$(id -u)" = 0 ]; then apt-get install -y python3-pip >/dev/null; else sudo apt-get install -y python3-pip >/dev/null; fi
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "install_oidn: downloading the pyoidn wheel (about 90 MB) from PyPI"
python3 -m pip download --quiet --no-deps --only-binary=:all: --platform manylinux2014_x86_64 -d "$tmp" pyoidn
wheel="$(ls "$tmp"/pyoidn-*.whl | head -n 1)"
rm -rf "$dest.new"
mkdir -p "$dest.new"
# Only the library folder is needed (the CPU device; the GPU ones are left out).
python3 - "$wheel" "$dest.new" <<'PY'
import sys, zipfile, os, stat
wheel, dest = sys.argv[1], sys.argv[2]
with zipfile.ZipFile(wheel) as z:
    for info in z.infolist():
        name = info.filename
        if not name.startswith("pyoidn/oidn/lib/") or name.endswith("/"):
            continue
        base = os.path.basename(name)
        if any(gpu in base for gpu in ("cuda", "hip", "sycl", "level_zero", "ur_", "umf")):
            continue
        z.extract(info, dest)
        os.chmod(os.path.join(dest, name), 0o755)
PY
rm -rf "$dest"
mv "$dest.new" "$dest"
echo "install_oidn: installed $(basename "$wheel") into $dest"
