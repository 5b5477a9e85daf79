//! Issue 22, pads with thickness (docs/physics.md section 13): the thin-layer law against the
//! paper's formula written here from Dimitriadis et al. (2002), bottoming out, the shipped padded
//! drop transfer against an energy-balance quadrature of the law, and the refusals.

use crate::common;
use applesim::contact::padding::PadConstants;
use applesim::contact::Material;
use applesim::scenario::{self, Scenario};
use common::*;
use serde_json::{json, Value};

const G: f64 = 9.81;

/// Dimitriadis, Horkay, Maresca, Kachar & Chadwick (2002), Biophys. J. 82:2798-2810, bonded
/// layer: F = 4/3 E/(1 - nu^2) R^(1/2) delta^(3/2) [1 - 2 a0/pi chi + 4 a0^2/pi^2 chi^2 -
/// 8/pi^3 (a0^3 + 4 pi^2 b0/15) chi^3 + 16 a0/pi^4 (a0^3 + 3 pi^2 b0/5) chi^4],
/// chi = sqrt(R delta)/h. Written from the paper, nothing of the crate's padding code.
fn dimitriadis_bonded(e: f64, nu: f64, r: f64, h: f64, delta: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let a0 = -(1.2876 - 1.4678 * nu + 1.3442 * nu.powi(2)) / (1.0 - nu);
    let b0 = (0.6387 - 1.0277 * nu + 1.5164 * nu.powi(2)) / (1.0 - nu);
    let chi = (r * delta).sqrt() / h;
    let series = 1.0 - 2.0 * a0 / pi * chi + 4.0 * a0.powi(2) / pi.powi(2) * chi.powi(2)
        - 8.0 / pi.powi(3) * (a0.powi(3) + 4.0 * pi.powi(2) * b0 / 15.0) * chi.powi(3)
        + 16.0 * a0 / pi.powi(4) * (a0.powi(3) + 3.0 * pi.powi(2) * b0 / 5.0) * chi.powi(4);
    4.0 / 3.0 * e / (1.0 - nu * nu) * r.sqrt() * delta.powf(1.5) * series
}

/// Acceptance 1: a rigid sphere (a 1e13 Pa "apple": its compliance is 1e-7 of the pad's) on a
/// foam layer at h = 4a, 2a and a (chi = 0.25, 0.5, 1; h = a/2 is chi = 2, beyond the series).
#[test]
fn the_pad_law_is_dimitriadis_bonded_layer_at_three_thickness_ratios() {
    let rigid = Material::from_youngs(1e13, 0.3, Some(7800.0)).unwrap();
    let steel = Material::from_shear(8.1e10, 0.28, None).unwrap();
    let (r, delta): (f64, f64) = (0.0375, 1e-3);
    let a = (r * delta).sqrt();
    let mut worst: f64 = 0.0;
    for (e, nu) in [(2e6, 0.3), (5e5, 0.45), (1e6, 0.1)] {
        let foam = Material::from_youngs(e, nu, None).unwrap();
        for h in [4.0 * a, 2.0 * a, a * (1.0 + 1e-9)] {
            let pad = PadConstants::new(&rigid, &foam, &steel, h, r, [0.9; 3]);
            let (f, bottomed) = pad.elastic_force(delta);
            assert!(!bottomed, "h = {h}");
            let want = dimitriadis_bonded(e, nu, r, h, delta);
            let err = rel(f, want).abs();
            println!(
                "E {e} nu {nu} h/a {:.2}: {f:.6} N against {want:.6} N ({err:.2e})",
                h / a
            );
            worst = worst.max(err);
            // Stiffer than the half-space.
            assert!(f > dimitriadis_bonded(e, nu, r, 1e3, delta));
        }
    }
    // docs/physics.md 13.4: within 1e-6 (measured 5.9e-7: the rigid sphere's compliance).
    assert!(worst < 1e-6, "worst {worst:e}");
}

fn drop_on(padding: Option<Value>, v0: f64) -> Value {
    let mut plate = json!({"name": "plate", "type": "plane", "material": "steel",
                           "point_m": [0, 0, 0], "normal": [0, 0, 1]});
    if let Some(p) = padding {
        plate["padding"] = p;
    }
    json!({
        "duration_s": 0.03, "time_step_s": 2e-6, "gravity_m_s2": [0, 0, -G],
        "output": {"sample_interval_s": 1e-3, "force_history": false},
        "materials": {
            "apple": {"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"shear_modulus_pa": 8.1e10, "poisson_ratio": 0.28},
            "foam": {"youngs_modulus_pa": 2e6, "poisson_ratio": 0.3}
        },
        "contact": {"friction": 0.3, "ke": 1.0, "lambda_s_m": 1000, "rolling": "none"},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 0.08, "mass_kg": 0.107,
                    "position_m": [0, 0, 0.0401], "velocity_m_s": [0, 0, -v0]}],
        "surfaces": [plate]
    })
}

fn parse(v: &Value) -> Scenario {
    scenario::from_json(&v.to_string(), "padding").unwrap()
}

fn plate_peak(sc: &Scenario) -> (f64, Vec<String>) {
    let (r, _) = run(sc);
    let e = r
        .events
        .iter()
        .find(|e| &*e.b == "plate")
        .expect("an impact");
    (e.peak_force_n, r.warnings)
}

/// Acceptance 2: the Fig. 1 apple at 1.4 m/s on 0.5 mm of foam bonded on steel bottoms out
/// (warned, naming apple, surface and time) and hits nearly as hard as on bare steel.
#[test]
fn a_hard_drop_on_a_thin_pad_bottoms_out_with_a_warning() {
    let (bare, bare_warnings) = plate_peak(&parse(&drop_on(None, 1.4)));
    assert!(bare_warnings.iter().all(|w| !w.contains("bottomed")));
    let (thin, warnings) = plate_peak(&parse(&drop_on(
        Some(json!({"material": "foam", "thickness_m": 0.0005})),
        1.4,
    )));
    let (thick, thick_warnings) = plate_peak(&parse(&drop_on(
        Some(json!({"material": "foam", "thickness_m": 0.02})),
        1.4,
    )));
    println!("peak: bare {bare:.3} N, 0.5 mm pad {thin:.3} N, 20 mm pad {thick:.3} N");
    println!("{warnings:?}");
    let w: Vec<&String> = warnings.iter().filter(|w| w.contains("bottomed")).collect();
    assert_eq!(w.len(), 1, "{warnings:?}");
    assert!(
        w[0].starts_with(
            "pad of surface 'plate' (0.5 mm of foam) bottomed out under apple 'a1' at t = 0.0"
        ),
        "{}",
        w[0]
    );
    assert!(thick_warnings.iter().all(|w| !w.contains("bottomed")));
    // Before it bottomed out (its half-space share would compress it 90 % at 0.8 mm of
    // overlap), it passed the law's validity at chi = 1: h / R* = 1.25 % compression.
    let v: Vec<&String> = warnings
        .iter()
        .filter(|w| w.contains("beyond the thin-layer law's validity"))
        .collect();
    assert_eq!(v.len(), 1, "{warnings:?}");
    assert!(
        v[0].contains("compressed 1.2 % of its thickness"),
        "{}",
        v[0]
    );
    // docs/physics.md 13.3: the thin pad's peak 100.032 N against bare steel's 100.035 N
    // (-0.003 %, checked with its sign at twice that; the 2 % looser); the 20 mm pad's
    // 81.19 N (to the digit) under 0.9 of bare.
    let off = thin / bare - 1.0;
    println!("thin pad against bare steel: {:+.4} %", 100.0 * off);
    assert!((-2.0 * 0.003e-2..0.0).contains(&off), "{off}");
    assert!((thin - 100.032).abs() <= 0.001 && (bare - 100.035).abs() <= 0.001);
    assert!(
        (thick - 81.19).abs() <= 0.01 && thick < 0.9 * bare,
        "{thick}"
    );
}

/// Issue 26: pads of 3 mm under a 20 cm drop and 10 mm under a 40 cm drop pass chi = 1 at
/// 7.5 % and 25 % compression (h / R*): the warning says the law's validity ended, not that the
/// pad bottomed out (the apple does not reach the substrate: the pad's share of the overlap
/// stays under 90 % of its thickness).
#[test]
fn the_end_of_the_laws_validity_is_not_a_bottomed_pad() {
    for (h, drop_m, pct) in [(0.003, 0.2, "7.5"), (0.01, 0.4, "25")] {
        let v = (2.0 * G * drop_m).sqrt();
        let (_, warnings) = plate_peak(&parse(&drop_on(
            Some(json!({"material": "foam", "thickness_m": h})),
            v,
        )));
        println!("{h} m: {warnings:?}");
        assert!(
            warnings.iter().all(|w| !w.contains("bottomed")),
            "{warnings:?}"
        );
        let w: Vec<&String> = warnings
            .iter()
            .filter(|w| w.contains("beyond the thin-layer law's validity"))
            .collect();
        assert_eq!(w.len(), 1, "{warnings:?}");
        assert!(
            w[0].contains(&format!("compressed {pct} % of its thickness")),
            "{}",
            w[0]
        );
        assert!(w[0].contains("the pad is not crushed"), "{}", w[0]);
    }
}

/// Acceptance 3: the shipped padded transfer and its bare twin. The padded landing's peak force is
/// predicted by the energy balance of the pad law, 1/2 m v^2 + m g u = integral of F du, with
/// the law written here from the paper and section 13's split and bottoming rules.
#[test]
fn the_padded_transfer_softens_the_landing_as_the_pad_law_predicts() {
    let (padded, _) = run(&shipped("scenarios/lines/padded_transfer.json"));
    let (bare, _) = run(&shipped("scenarios/lines/padded_transfer_bare.json"));
    let landing = |r: &applesim::sim::RunResult| {
        r.events
            .iter()
            .filter(|e| &*e.b == "plate")
            .min_by(|a, b| a.t_start_s.total_cmp(&b.t_start_s))
            .cloned()
            .expect("a landing")
    };
    let (p, b) = (landing(&padded), landing(&bare));
    assert!(padded.warnings.iter().all(|w| !w.contains("bottomed")));
    // The apple: apple-paper (G 1.1 MPa, nu 0.18, 800 kg/m^3), D 75 mm; foam E 2 MPa, nu 0.3,
    // 12 mm; steel G 8.1e10 Pa, nu 0.28.
    let r: f64 = 0.0375;
    let m = 800.0 * std::f64::consts::PI / 6.0 * 0.075f64.powi(3);
    let c = |e: f64, nu: f64| (1.0 - nu * nu) / e;
    let ca = c(2.0 * 1.1e6 * 1.18, 0.18);
    let cp = c(2e6, 0.3);
    let cs = c(2.0 * 8.1e10 * 1.28, 0.28);
    let h = 0.012;
    let s = cp / (ca + cp);
    let pad_force = |u: f64| {
        if u <= 0.0 {
            return 0.0;
        }
        // The pad's part s u of the overlap sets chi; f stiffens the pad's compliance.
        let delta = s * u;
        let f_chi =
            dimitriadis_bonded(1.0, 0.3, r, h, delta) / dimitriadis_bonded(1.0, 0.3, r, 1e6, delta);
        4.0 / 3.0 * r.sqrt() / (ca + cp / f_chi) * u.powf(1.5)
    };
    let bare_force = |u: f64| 4.0 / 3.0 * r.sqrt() / (ca + cs) * u.powf(1.5);
    let peak = |force: &dyn Fn(f64) -> f64, v: f64| {
        let (mut u, mut w, du) = (0.0f64, 0.0f64, 1e-8);
        while w < 0.5 * m * v * v + m * G * u {
            w += 0.5 * (force(u) + force(u + du)) * du;
            u += du;
        }
        assert!(
            s * u < h && (r * s * u).sqrt() / h < 1.0,
            "within the series"
        );
        force(u)
    };
    let want_p = peak(&pad_force, p.approach_speed_m_s);
    let want_b = peak(&bare_force, b.approach_speed_m_s);
    println!(
        "padded {:.2} N (predicted {want_p:.2} N), bare {:.2} N (predicted {want_b:.2} N), at {:.4} / {:.4} m/s",
        p.peak_force_n, b.peak_force_n, p.approach_speed_m_s, b.approach_speed_m_s
    );
    // docs/lines.md section 5: +0.09 % (padded) and +0.20 % (bare) above the prediction (the issue:
    // 1 %), each checked with its sign at twice that.
    assert_rel("padded peak", p.peak_force_n, want_p, 2.0 * 0.09e-2);
    assert_rel("bare peak", b.peak_force_n, want_b, 2.0 * 0.20e-2);
    assert!(p.peak_force_n > want_p && b.peak_force_n > want_b);
    // The reduction the law predicts.
    let (got, want) = (1.0 - p.peak_force_n / b.peak_force_n, 1.0 - want_p / want_b);
    println!(
        "reduction {:.2} % (predicted {:.2} %)",
        100.0 * got,
        100.0 * want
    );
    // 12.51 % against the predicted 12.42 %: 0.09 points more, checked at twice that.
    assert!(got > want && got - want <= 2.0 * 0.09e-2, "{got} {want}");
}

fn refusal(v: &Value) -> String {
    match scenario::from_json(&v.to_string(), "padding") {
        Err(e) => e.to_string(),
        Ok(sc) => scenario::validate(&sc).unwrap_err().to_string(),
    }
}

/// Acceptance 4: the refusals name the field.
#[test]
fn bad_paddings_are_refused_naming_the_field() {
    let with = |surface: Value| {
        json!({
            "duration_s": 0.1, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -G],
            "materials": {"steel": {"shear_modulus_pa": 8.1e10, "poisson_ratio": 0.28},
                          "foam": {"youngs_modulus_pa": 2e6, "poisson_ratio": 0.3}},
            "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
            "surfaces": [surface]
        })
    };
    let plane = |pad: Value| {
        with(
            json!({"name": "p", "type": "plane", "material": "steel", "point_m": [0, 0, 0],
                    "normal": [0, 0, 1], "padding": pad}),
        )
    };
    let pad = json!({"material": "foam", "thickness_m": 0.01});
    let cases = [
        (
            plane(json!({"material": "felt", "thickness_m": 0.01})),
            "surfaces[0].padding.material: unknown material 'felt': there is no materials.felt (defined: foam, steel)",
        ),
        (
            plane(json!({"material": "foam", "thickness_m": 0})),
            "surfaces[0].padding.thickness_m: 0 m is outside the range of fruit handling (0 m < h <= 0.1 m)",
        ),
        (
            plane(json!({"material": "foam", "thickness_m": -0.01})),
            "surfaces[0].padding.thickness_m: -0.01 m is outside the range of fruit handling (0 m < h <= 0.1 m)",
        ),
        (
            plane(json!({"material": "foam", "thickness_m": 0.5})),
            "surfaces[0].padding.thickness_m: 0.5 m is outside the range of fruit handling (0 m < h <= 0.1 m)",
        ),
        (
            with(json!({"name": "p", "type": "plane", "material": "steel", "point_m": [0, 0, 0],
                        "normal": [0, 0, 1], "contact_model": "rigid", "padding": pad})),
            "surfaces[0].padding: a rigid surface (rapier's own contact) cannot model a pad: use the hertz contact_model",
        ),
        (
            with(json!({"name": "t", "type": "chute", "material": "steel", "profile": "trough",
                        "radius_m": 0.1, "length_m": 1, "position_m": [0, 0, 0], "padding": pad})),
            "surfaces[0].padding: padding is for flat surfaces: the thin-layer law is for a flat layer, not a trough",
        ),
    ];
    for (v, want) in cases {
        assert_eq!(refusal(&v), want);
    }
    // Surface types without padding: refused when read, naming the field.
    for (t, extra) in [
        (
            "conveyor",
            json!({"size_m": [1, 0.3, 0.04], "position_m": [0, 0, 0], "belt_velocity_m_s": 0.5}),
        ),
        (
            "bin",
            json!({"inner_size_m": [0.5, 0.5, 0.3], "position_m": [0, 0, 0]}),
        ),
        ("mesh", json!({"file": "x.obj", "position_m": [0, 0, 0]})),
        (
            "roller",
            json!({"radius_m": 0.03, "length_m": 0.5, "position_m": [0, 0, 0], "angular_velocity_rad_s": 1}),
        ),
    ] {
        let mut s = json!({"name": "s", "type": t, "material": "steel", "padding": pad});
        for (k, v) in extra.as_object().unwrap() {
            s[k] = v.clone();
        }
        let e = refusal(&with(s));
        println!("{e}");
        assert!(e.contains("surfaces[0].padding"), "{e}");
        assert!(
            e.contains(&format!(
                "padding is for planes, boxes and flat chutes, not a {t}"
            )),
            "{e}"
        );
    }
    // A padded box and a padded flat chute are fine.
    for s in [
        json!({"name": "b", "type": "box", "material": "steel", "size_m": [1, 1, 0.02], "position_m": [0, 0, 0], "padding": pad}),
        json!({"name": "c", "type": "chute", "material": "steel", "profile": "flat", "width_m": 0.3,
               "length_m": 1, "position_m": [0, 0, 0], "padding": pad}),
    ] {
        let sc = parse(&with(s));
        // (It lacks apples, which is all validation finds.)
        let e = scenario::validate(&sc).unwrap_err().to_string();
        assert!(!e.contains("padding"), "{e}");
    }
}
