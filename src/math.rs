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
