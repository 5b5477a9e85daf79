//! Contact geometry of undeformed shapes: overlap ("hard convergence", paper eq. 8), normal and
//! contact point. Pure functions of positions.

use crate::math::Vec3;

/// Overlap and normal of two spheres, or `None` when they are apart.
///
/// u = R1 + R2 - |c1 - c2|; the normal points from sphere 2 to sphere 1 (the direction of the
/// force on sphere 1). Coincident centres (a degenerate input) give `None`: no direction exists.
pub fn sphere_sphere(c1: Vec3, r1: f64, c2: Vec3, r2: f64) -> Option<(Vec3, f64)> {
    let d = c1 - c2;
    let dist2 = d.length_squared();
    let reach = r1 + r2;
    if dist2 >= reach * reach || dist2 == 0.0 {
        return None;
    }
    let dist = dist2.sqrt();
    Some((d / dist, reach - dist))
}

/// Overlap of a sphere with the half-space below a plane (eq. 8): u = R - signed distance of the
/// centre. `normal` is the plane's unit outward normal. May be <= 0 (apart).
pub fn sphere_plane(c: Vec3, r: f64, point: Vec3, normal: Vec3) -> f64 {
    r - (c - point).dot(normal)
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
        let (n, u) = sphere_sphere(
            Vec3::new(0.0, 0.0, 0.079),
            0.04,
            Vec3::new(0.0, 0.0, 0.0),
            0.04,
        )
        .unwrap();
        assert!((u - 0.001).abs() < 1e-15);
        assert_eq!(n, Vec3::new(0.0, 0.0, 1.0));
        assert!(sphere_sphere(Vec3::new(0.0, 0.0, 0.08), 0.04, Vec3::ZERO, 0.04).is_none());
        assert!(sphere_sphere(Vec3::ZERO, 0.04, Vec3::ZERO, 0.04).is_none());
    }

    #[test]
    fn plane_and_lever_arm() {
        let u = sphere_plane(Vec3::new(1.0, 2.0, 0.039), 0.04, Vec3::ZERO, Vec3::Z);
        assert!((u - 0.001).abs() < 1e-15);
        let c = contact_point(Vec3::new(0.0, 0.0, 0.039), 0.04, Vec3::Z, u, 1.0);
        assert!(c.z.abs() < 1e-15, "rigid flat: contact on the plane");
        let c_half = contact_point(Vec3::new(0.0, 0.0, 0.079), 0.04, Vec3::Z, 0.001, 0.5);
        assert!((c_half.z - 0.0395).abs() < 1e-15, "equal apples: mid-plane");
    }
}
