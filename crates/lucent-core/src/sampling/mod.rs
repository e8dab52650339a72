//! Floor 0 — turning uniform random numbers into the distributions the Monte Carlo
//! integrators draw from, with the density of each: directions on the hemisphere
//! (uniform, cosine-weighted, a Phong lobe, GGX half vectors), the orthonormal frame
//! around a normal they are drawn in, and the power heuristic that weighs two strategies
//! (multiple importance sampling), and piecewise-constant distributions over intervals
//! and grids ([`distribution`]: environment-map texels, emissive primitives). Points on quad lights are in [`crate::light`].
//!
//! Every routine here has a χ² goodness-of-fit test against its own density
//! ([`chi2`], used by the BSDF and light tests too).

pub mod distribution;
pub mod frame;
pub mod mis;
pub mod warp;

#[cfg(test)]
pub mod chi2;

/// The largest f32 below 1: where a number in [0, 1) made from another must stay.
pub const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;
