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

/// A time as a person writes it: 4 significant digits, at least to the millisecond
/// (0.030000000000000002 -> 0.03, 2.41237 -> 2.412, 1234.5678 -> 1234.568).
pub fn secs(t: f64) -> String {
    human(t, 4, 3)
}

/// `x` rounded to `sig` significant digits, but never coarser than `decimals` decimals, printed
/// without trailing zeros.
pub fn human(x: f64, sig: usize, decimals: i32) -> String {
    if !x.is_finite() || x == 0.0 {
        return x.to_string();
    }
    let magnitude = x.abs().log10().floor() as i32;
    let d = (sig as i32 - 1 - magnitude).max(decimals).clamp(0, 17);
    let s = format!("{x:.*}", d as usize);
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

/// A step length as a person writes it: 4 significant digits, small ones as 5e-5.
pub fn step(x: f64) -> String {
    if x != 0.0 && x.abs() < 1e-3 {
        sci(x)
    } else {
        human(x, 4, 0)
    }
}

/// `x` in e-notation to 4 significant digits, without trailing zeros (2.4e-4, 1e-3).
fn sci(x: f64) -> String {
    let rounded: f64 = format!("{x:.3e}").parse().unwrap_or(x);
    format!("{rounded:e}")
}

/// An adaptive run's shortest and longest steps, both written alike ("2.4e-4 to 1e-3", not
/// "2.4e-4 to 0.001").
pub fn step_range(lo: f64, hi: f64) -> String {
    if lo != 0.0 && lo.abs() < 1e-3 {
        format!("{} to {}", sci(lo), sci(hi))
    } else {
        format!("{} to {}", step(lo), step(hi))
    }
}

#[cfg(test)]
mod human_tests {
    use super::*;

    #[test]
    fn times_and_steps_as_people_write_them() {
        assert_eq!(secs(0.030000000000000002), "0.03");
        assert_eq!(secs(10.0), "10");
        assert_eq!(step(5e-5), "5e-5");
        assert_eq!(step(1.25e-4), "1.25e-4");
        assert_eq!(step(0.0016666), "0.001667");
        assert_eq!(step_range(2.4e-4, 1e-3), "2.4e-4 to 1e-3");
    }
}
