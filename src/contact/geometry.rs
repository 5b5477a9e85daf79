//! Contact geometry of undeformed shapes: overlap ("hard convergence", paper eq. 8), normal and
//! contact point. Pure functions of positions.

use crate::math::Vec3;

/// Normal and overlap of two spheres from the offset of their centres d = c1 - c2 and its squared
/// length (the caller has it: pair detection compares |d|^2 with (R1 + R2)^2 before taking any
/// root, and skips the pairs that are apart).
///
/// u = R1 + R2 - |d| (paper eq. 8 for two spheres; <= 0 when apart); the normal points from
/// sphere 2 to sphere 1 (the direction of the force on sphere 1). Coincident centres (a degenerate
/// input only a broken scene produces) give the normal +z.
#[inline]
pub fn sphere_sphere(d: Vec3, dist2: f64, reach_m: f64) -> (Vec3, f64) {
    let dist = dist2.sqrt();
    let n = if dist > 0.0 {
        d * (1.0 / dist)
    } else {
        Vec3::Z
    };
    (n, reach_m - dist)
}

/// Overlap of a sphere with the half-space below a plane (eq. 8): u = R - signed distance of the
/// centre. The plane is given by its unit outward normal and its offset n . p for any point p on
/// it (the layer reads both once per step). May be <= 0 (apart).
#[inline]
pub fn sphere_plane(c: Vec3, r: f64, normal: Vec3, offset_m: f64) -> f64 {
    r - (c.dot(normal) - offset_m)
}

/// Contact point on the contact plane: at distance R1 - u share1 from body 1's centre along -n,
/// where share1 = c1 / (c1 + c2) is body 1's part of the overlap (physics.md section 5). This is the
/// friction lever arm: R - u on a rigid flat, R - u/2 between two equal apples.
pub fn contact_point(c1: Vec3, r1: f64, normal: Vec3, overlap_m: f64, share1: f64) -> Vec3 {
    c1 - normal * (r1 - overlap_m * share1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_pair() {
        let d = Vec3::new(0.0, 0.0, 0.079);
        let (n, u) = sphere_sphere(d, d.length_squared(), 0.08);
        assert!((u - 0.001).abs() < 1e-15);
        assert!((n - Vec3::Z).length() < 1e-15);
        let apart = Vec3::new(0.0, 0.0, 0.081);
        assert!(sphere_sphere(apart, apart.length_squared(), 0.08).1 < 0.0);
        assert_eq!(sphere_sphere(Vec3::ZERO, 0.0, 0.08), (Vec3::Z, 0.08));
    }

    #[test]
    fn plane_and_lever_arm() {
        let u = sphere_plane(Vec3::new(1.0, 2.0, 0.039), 0.04, Vec3::Z, 0.0);
        let raised = sphere_plane(Vec3::new(1.0, 2.0, 0.539), 0.04, Vec3::Z, 0.5);
        assert!(
            (raised - 0.001).abs() < 1e-15,
            "offset n . p of a raised plane"
        );
        assert!((u - 0.001).abs() < 1e-15);
        let c = contact_point(Vec3::new(0.0, 0.0, 0.039), 0.04, Vec3::Z, u, 1.0);
        assert!(c.z.abs() < 1e-15, "rigid flat: contact on the plane");
        let c_half = contact_point(Vec3::new(0.0, 0.0, 0.079), 0.04, Vec3::Z, 0.001, 0.5);
        assert!((c_half.z - 0.0395).abs() < 1e-15, "equal apples: mid-plane");
    }
}
