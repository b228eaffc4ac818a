//! What the Pioneer kinematics tests share: vectors from arrays, the default geometry and
//! IK options.

use limber_kinematics::pioneer::{PioneerGeometry, PioneerIkOptions};
use nalgebra::Vector3;

/// A vector from its three components.
pub fn v(a: [f64; 3]) -> Vector3<f64> {
    Vector3::from(a)
}

/// The Pioneer arm's default geometry.
pub fn geom() -> PioneerGeometry {
    PioneerGeometry::default()
}

/// The default IK options.
pub fn opts() -> PioneerIkOptions {
    PioneerIkOptions::default()
}
