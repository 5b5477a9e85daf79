//! The shape of a bruise: a spherical cap of surface diameter d and depth h (the form the
//! literature measures bruises in, bruise-models.md section 5), and the part of a Hertz patch
//! above a pressure.

use std::f64::consts::PI;

/// Volume of a spherical cap of surface diameter `d` and depth `h` (any length unit, cubed):
/// pi h (3 d^2 + 4 h^2) / 24.
pub fn cap_volume(d: f64, h: f64) -> f64 {
    PI * h * (3.0 * d * d + 4.0 * h * h) / 24.0
}

/// Depth of the spherical cap of surface diameter `d` and volume `v`: the one real root of
/// h^3 + (3/4) d^2 h - 6 v / pi = 0 (the cap volume is increasing in h), by Cardano's formula.
/// 0 for `v` <= 0.
pub fn cap_depth(v: f64, d: f64) -> f64 {
    if v <= 0.0 {
        return 0.0;
    }
    if d <= 0.0 {
        // A cap of no width: a hemisphere-less "needle" has no volume; fall back to the cube
        // root of a sphere's 6 v / pi (h^3 = 6 v / pi).
        return (6.0 * v / PI).cbrt();
    }
    let p = 0.75 * d * d;
    let q = -6.0 * v / PI;
    let disc = (q * q / 4.0 + p * p * p / 27.0).sqrt();
    let h = (-q / 2.0 + disc).cbrt() + (-q / 2.0 - disc).cbrt();
    // One Newton step polishes the cancellation of the two cube roots when v is small.
    let f = h * h * h + p * h + q;
    h - f / (3.0 * h * h + p)
}

/// The diameter and depth of a bruise of volume `v` whose full shape is the cap (`d0`, `h0`):
/// a smaller volume is the same shape scaled down (both by (v / V0)^(1/3), V0 the full cap's
/// volume): a bruise starts small under the contact and grows; a larger one keeps the full width
/// and goes deeper (the cap of volume `v` on `d0`). (0, 0) for `v` <= 0.
pub fn shaped_cap(v: f64, d0: f64, h0: f64) -> (f64, f64) {
    if v <= 0.0 {
        return (0.0, 0.0);
    }
    let v0 = cap_volume(d0, h0);
    if v0 > 0.0 && v <= v0 {
        let k = (v / v0).cbrt();
        (d0 * k, h0 * k)
    } else {
        (d0, cap_depth(v, d0))
    }
}

/// Area of the part of a Hertz patch of radius `a` and centre pressure `p0` where the pressure
/// p(r) = p0 sqrt(1 - r^2/a^2) is at least `p_c`: pi a^2 (1 - (p_c/p0)^2) when p0 > p_c, else 0
/// (bruise-models.md M6, the Hertz mapping \[INF\]).
pub fn area_above_pressure(a: f64, p0: f64, p_c: f64) -> f64 {
    if p0 <= p_c || a <= 0.0 {
        return 0.0;
    }
    let r = p_c / p0;
    PI * a * a * (1.0 - r * r)
}

/// Diameter of a disc of area `area`.
pub fn disc_diameter(area: f64) -> f64 {
    2.0 * (area.max(0.0) / PI).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cap_figures_of_the_literature_file() {
        // bruise-models.md section 5: EU 1 cm^2 (d = 11.3 mm) at h = 3 / 5 / 8 mm: 164 / 315 /
        // 668 mm^3; WA injury at the limit (15.9 x 3.2 mm): ~331 mm^3.
        for (d, h, v) in [(11.3, 3.0, 164.0), (11.3, 5.0, 315.0), (11.3, 8.0, 668.0)] {
            assert!((cap_volume(d, h) / v - 1.0).abs() < 0.005, "{d} {h}");
        }
        // Printed "about 331": the formula gives 334.8 (+1.1 %).
        assert!((cap_volume(15.9, 3.2) / 331.0 - 1.0).abs() < 0.012);
        // A hemisphere: d = 2h gives (2/3) pi h^3.
        assert!((cap_volume(2.0, 1.0) - 2.0 / 3.0 * PI).abs() < 1e-14);
    }

    #[test]
    fn depth_inverts_the_volume() {
        for &(d, h) in &[
            (11.3, 3.0),
            (15.9, 3.2),
            (1.0, 10.0),
            (30.0, 1e-4),
            (5.0, 2.5),
        ] {
            let v = cap_volume(d, h);
            assert!(
                (cap_depth(v, d) / h - 1.0).abs() < 1e-12,
                "{d} {h} {}",
                cap_depth(v, d)
            );
        }
        assert_eq!(cap_depth(0.0, 5.0), 0.0);
    }

    #[test]
    fn shaped_caps_scale_below_the_full_volume_and_deepen_above() {
        let (d0, h0) = (16.0, 6.0);
        let v0 = cap_volume(d0, h0);
        let (d, h) = shaped_cap(v0 / 8.0, d0, h0);
        assert!((d - 8.0).abs() < 1e-12 && (h - 3.0).abs() < 1e-12);
        assert!((cap_volume(d, h) - v0 / 8.0).abs() < 1e-9);
        let (d, h) = shaped_cap(2.0 * v0, d0, h0);
        assert_eq!(d, d0);
        assert!(h > h0 && (cap_volume(d, h) / (2.0 * v0) - 1.0).abs() < 1e-12);
        assert_eq!(shaped_cap(0.0, d0, h0), (0.0, 0.0));
    }

    #[test]
    fn patch_above_a_pressure() {
        let a = 6e-3;
        assert_eq!(area_above_pressure(a, 1e5, 2e5), 0.0);
        // Half the centre pressure: r/a = sqrt(3)/2, area 3/4 of the patch.
        let full = PI * a * a;
        assert!((area_above_pressure(a, 2e5, 1e5) / full - 0.75).abs() < 1e-14);
        assert!((disc_diameter(full) - 2.0 * a).abs() < 1e-15);
    }
}
