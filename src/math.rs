//! Vector types shared by every stage: rapier's own (glam `DVec3`, f64), so no conversion is
//! needed between the contact law and the bodies it acts on.

/// A 3-vector in metres, m/s, N, ... (rapier's `Vector`, glam `DVec3`).
pub type Vec3 = rapier3d_f64::math::Vector;

/// True when every component is finite.
pub fn is_finite(v: Vec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

/// Vector from a JSON-style array.
pub fn vec3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// JSON-style array from a vector.
pub fn arr3(v: Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}
