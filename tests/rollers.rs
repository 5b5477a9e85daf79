//! Rollers (issue 22, the parts issue 22 left): the exact ellipse of a roller contact, free-turning
//! rollers with their own inertia, roller beds and a rotating brush, against closed forms written
//! here from docs/physics.md section 12 (each with its tolerance and the figure measured with this
//! build, docs/physics.md 12.6).

mod common;
use applesim::contact::{elliptic, material::Material};
use applesim::scenario::{self, Scenario};
use common::*;
use serde_json::{json, Value};
use std::f64::consts::PI;

const APPLE: (f64, f64) = (1.0e6, 0.18);
const STEEL: (f64, f64) = (8.1e10, 0.28);

fn materials() -> Value {
    json!({
        "apple": {"shear_modulus_pa": APPLE.0, "poisson_ratio": APPLE.1, "density_kg_m3": 800},
        "steel": {"shear_modulus_pa": STEEL.0, "poisson_ratio": STEEL.1}})
}

fn e_star_of(a: (f64, f64), b: (f64, f64)) -> f64 {
    let ea = Material::from_shear(a.0, a.1, None).unwrap().youngs_modulus_pa;
    let eb = Material::from_shear(b.0, b.1, None).unwrap().youngs_modulus_pa;
    1.0 / ((1.0 - a.1 * a.1) / ea + (1.0 - b.1 * b.1) / eb)
}

fn parse(v: &Value) -> Scenario {
    scenario::from_json(&v.to_string(), "rollers").unwrap()
}

/// Johnson, Contact Mechanics (1985), section 4.2, written here: the semi-axes a >= b of the
/// contact ellipse of two bodies with principal relative radii R' >= R'' under a load P. The axis
/// ratio x = b/a solves R'/R'' = (E(e)/x^2 - K(e)) / (K(e) - E(e)) (e^2 = 1 - x^2; bisection,
/// the ratio falls as x grows), then A = 1/(2R') = 3 P (K - E) / (2 pi E* e^2 a^3).
fn johnson_ellipse(r1: f64, r2: f64, e_star: f64, p: f64) -> (f64, f64) {
    let ratio = |x: f64| {
        let (k, e) = elliptic::elliptic_k_e(1.0 - x * x);
        (e / (x * x) - k) / (k - e)
    };
    let (mut lo, mut hi) = (1e-6, 1.0 - 1e-12);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) > r1 / r2 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let x = 0.5 * (lo + hi);
    let m = 1.0 - x * x;
    let (k, e) = elliptic::elliptic_k_e(m);
    let a = (3.0 * p * (k - e) / (2.0 * PI * e_star * m * (0.5 / r1))).cbrt();
    (a, x * a)
}

/// Item 4: an apple (37 mm, 0.107 kg) dropped at 1 m/s on fixed steel rollers of 20 and 60 mm (no
/// gravity, elastic). At the peak the recorded contact radius is that of the true area,
/// pi r^2 = pi a b, and the recorded mean pressure P / (pi a b), with a and b from Johnson's
/// equations at the recorded peak force: to 1e-6 (measured: 1e-9 or better). The law's own
/// radius sqrt(R_k u) would be 3.0 % (20 mm) and 0.64 % (60 mm) high.
#[test]
fn a_roller_contact_reports_the_area_and_pressure_of_the_true_ellipse() {
    let (ra, m, v0) = (0.037, 0.107, 1.0);
    for rr in [0.02, 0.06] {
        let sc = parse(&json!({
            "duration_s": 0.012, "time_step_s": 2e-6, "gravity_m_s2": [0, 0, 0],
            "fidelity": "hertz",
            "output": {"sample_interval_s": 1e-3, "force_history": false},
            "materials": materials(),
            "contact": {"friction": 0.3, "ke": 1, "lambda_s_m": 0, "rolling": "none"},
            "model": {"sleep": {"enabled": false}},
            "apples": [{"name": "a1", "material": "apple", "diameter_m": 2.0 * ra, "mass_kg": m,
                "position_m": [0, 0, rr + ra + 1e-4], "velocity_m_s": [0, 0, -v0]}],
            "surfaces": [{"name": "roller", "type": "roller", "material": "steel", "radius_m": rr,
                "length_m": 0.3, "position_m": [0, 0, 0], "axis": [1, 0, 0]}]
        }));
        let (res, _) = run(&sc);
        let e = &res.events[0];
        let (a, b) = johnson_ellipse(
            ra,
            ra * rr / (ra + rr),
            e_star_of(APPLE, STEEL),
            e.peak_force_n,
        );
        let area = PI * a * b;
        let what = format!("R_r {rr}");
        assert_ref(
            &format!("{what}: contact area"),
            PI * e.max_contact_radius_m.powi(2),
            area,
            1e-6,
            "Johnson 4.2",
        );
        assert_ref(
            &format!("{what}: mean pressure"),
            e.max_pressure_pa,
            e.peak_force_n / area,
            1e-6,
            "Johnson 4.2",
        );
        let h = elliptic::sphere_on_cylinder(ra, rr);
        let law_radius = (h.stiffness_radius_m * e.max_overlap_m).sqrt();
        println!(
            "{what}: a = {:.4} mm, b = {:.4} mm, p0 = {:.1} kPa; sqrt(R_k u) would be {:+.2} % off sqrt(a b)",
            a * 1e3,
            b * 1e3,
            1.5 * e.max_pressure_pa / 1e3,
            100.0 * (law_radius / (a * b).sqrt() - 1.0)
        );
    }
}
