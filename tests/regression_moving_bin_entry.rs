//! Regression (issue 26 item 7): bin entry times ignored the bin's own motion: a lowered bin's
//! apples "entered" when they crossed the rim where it was at t = 0. Entry is measured against
//! the bin's pose at that moment.

use crate::common;
use applesim::scenario;
use applesim::sim::fate::Fate;
use common::*;

#[test]
fn an_apple_enters_a_lowered_bin_when_it_crosses_its_rim_where_the_rim_is_then() {
    // A 0.3 m deep bin lowered at 0.2 m/s from t = 0; an apple released at rest 0.8 m above its
    // floor. Its centre crosses the rim when 0.8 - g t^2 / 2 = 0.3 - 0.2 t.
    let (g, vb, h, z0): (f64, f64, f64, f64) = (9.81, 0.2, 0.3, 0.8);
    let text = format!(
        r#"{{
      "duration_s": 0.45, "time_step_s": 2e-5, "gravity_m_s2": [0, 0, -{g}],
      "output": {{ "sample_interval_s": 0.001, "force_history": false }},
      "materials": {{
        "apple": {{ "shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800 }},
        "plastic": {{ "shear_modulus_pa": 1e9, "poisson_ratio": 0.3 }}
      }},
      "contact": {{ "friction": 0.3, "ke": 0.09, "lambda_s_m": 1000 }},
      "apples": [ {{ "name": "a", "material": "apple", "diameter_m": 0.08,
                     "position_m": [0, 0, {z0}] }} ],
      "surfaces": [ {{ "name": "bin", "type": "bin", "material": "plastic",
                       "inner_size_m": [0.4, 0.4, {h}], "position_m": [0, 0, 0],
                       "motion": {{ "translation": {{ "velocity_m_s": [0, 0, -{vb}] }} }} }} ]
    }}"#
    );
    let sc = scenario::from_json(&text, "moving bin").unwrap();
    scenario::validate(&sc).unwrap();
    let (r, _) = run(&sc);
    // rapier's symplectic Euler puts a falling body at z0 - g t (t + dt) / 2 at step n, t = n dt
    // (3.3e-5 m below the parabola at 0.34 s): the crossing of that trajectory with the rim,
    // g t^2 / 2 + (g dt / 2 - vb) t - (z0 - h) = 0.
    let dt = 2e-5;
    let b = 0.5 * g * dt - vb;
    let t_moving = (-b + (b * b + 2.0 * g * (z0 - h)).sqrt()) / g;
    let t_fixed = (2.0 * (z0 - h) / g).sqrt();
    let bin = &r.line.throughput[0];
    let got = bin.entries[0].time_s;
    println!(
        "entered at {got:.6} s: the lowered rim {t_moving:.6} s, the rim at t = 0 {t_fixed:.6} s"
    );
    // Linear interpolation between 1 ms samples of a relative height that is quadratic in t:
    // off by at most g dt^2 / 8 over the closing speed (3.3 m/s), 4e-7 s; checked at 1e-6 s.
    assert!((got - t_moving).abs() < 1e-6, "{got} {t_moving}");
    assert!((got - t_fixed).abs() > 0.02);
    assert!(matches!(
        r.apples[0].fate,
        Fate::InBin { .. } | Fate::Moving { .. }
    ));
}
