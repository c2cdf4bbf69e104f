//! Several axes along one path (seed 002's Cartesian path following): the rules by which a
//! path length `s`, integrated by the chain, becomes each axis's position.
//!
//! Built so far: [`cordic`], the integer sine and cosine an arc's interpolator uses. The
//! interpolator itself, the element sequencer and the fabric are not built yet (issue 22).

pub mod cordic;
