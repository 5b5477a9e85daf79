//! Spheroidal apples on lines (issue 29; docs/lines.md section 4b): where they sit in a roller
//! singulator and about which axis they turn.

use crate::common;
use applesim::math::Vec3;
use common::*;

/// The roller singulator with apples of aspect 0.85 (D 75 mm, height 63.75 mm), 2-4.5 s, after
/// they have settled in their valleys. Two ways of turning, both measured on the bodies' samples:
///
/// - apple-3, axis along the rollers (y): a wheel. It spins about its own axis, which stays
///   along y, at w_r R_r / (a - u): the sphere's closed form with the equatorial radius a
///   (docs/lines.md section 4, 8.04 rad/s for the sphere of the same diameter; 8.048 here); its
///   centre stays at 54.08-54.11 mm.
/// - apple-1 (pole up), apple-2 (axis along the travel) and apple-4 (turned at random) all end
///   tumbling: their axis across the rollers (|axis . y| 0 for apple-1 and -2; apple-4 still
///   turning it out, 0.053 from 3 s), turning end over end about the rollers' direction
///   (|cos(w, y)| > 0.998), faster on the mean (8.85-9.05 rad/s over 3-4.5 s: the lever
///   alternates between a and c), the centre rising and falling between 49.6 and 51.3 mm as the
///   cheek and the poles pass over the rollers.
///
/// Figures as docs/lines.md prints them; held at their printed digits (regression pins of this
/// run, not closed forms, except the wheel's spin).
#[test]
fn spheroids_in_the_roller_singulator() {
    let sc = shipped("scenarios/lines/roller_singulator_spheroids.json");
    let (_, series) = run(&sc);
    let a = 0.0375;
    for k in 0..4u32 {
        let s: Vec<_> = series
            .of(k)
            .into_iter()
            .filter(|(t, _)| *t >= 3.0)
            .collect();
        assert!(s.len() > 100, "samples");
        let axis = |st: &applesim::record::series::AppleState| {
            st.shape.expect("a spheroid").rotation * Vec3::Z
        };
        let z: Vec<f64> = s.iter().map(|(_, st)| st.position.z).collect();
        let (zmin, zmax) = (
            z.iter().cloned().fold(f64::INFINITY, f64::min),
            z.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
        );
        let spin_y = s
            .iter()
            .map(|(_, st)| st.angular_velocity.y.abs() / st.angular_velocity.length())
            .fold(f64::INFINITY, f64::min);
        let w_mean = s
            .iter()
            .map(|(_, st)| st.angular_velocity.length())
            .sum::<f64>()
            / s.len() as f64;
        let axis_y = s
            .iter()
            .map(|(_, st)| axis(st).y.abs())
            .fold(f64::NEG_INFINITY, f64::max);
        println!(
            "apple-{}: z {zmin:.5}-{zmax:.5} m, |w| mean {w_mean:.3} rad/s, min |cos(w, y)| {spin_y:.5}, max |axis . y| {axis_y:.4}",
            k + 1
        );
        assert!(spin_y > 0.998, "turns about the rollers' direction");
        if k == 2 {
            // The wheel: own axis along y, spin w_r R_r / (a - u) (no slip at either roller),
            // above w_r R_r / a by the lever's overlap (u/a: +0.5 % for the sphere of section 4).
            let closed = 10.0 * 0.03 / a;
            assert!(axis_y > 0.999, "wheel: axis along the rollers");
            let excess = w_mean / closed - 1.0;
            assert!(
                excess > 0.0 && excess < 0.01,
                "wheel spin {w_mean} against {closed}"
            );
            assert!((zmin - 0.05408).abs() < 2e-5 && (zmax - 0.05411).abs() < 2e-5);
        } else {
            // apple-4 is still turning its axis out of y (0.061 at 2 s, 0.053 from 3 s).
            assert!(axis_y < 0.06, "tumbling: axis across the rollers");
            assert!(w_mean > 8.8 && w_mean < 9.1, "tumbling spin {w_mean}");
            assert!((zmin - 0.0496).abs() < 2e-4 && (zmax - 0.0513).abs() < 2e-4);
        }
    }
}

/// (highest apple top, mean centre height, |axis . z| of each apple) at the end of a run.
fn heap(rel: &str) -> (f64, f64, Vec<f64>) {
    let sc = shipped(rel);
    let (r, series) = run(&sc);
    assert_eq!(r.apples.len(), 500, "every apple fed");
    let (_, last) = series.samples.last().expect("samples");
    let mut top: f64 = 0.0;
    let mut mean = 0.0;
    let mut tilt = Vec::new();
    for st in last {
        let a = 0.5 * st.diameter_m;
        let h = match &st.shape {
            Some(sh) => {
                let axz = (sh.rotation * Vec3::Z).z;
                tilt.push(axz.abs());
                let c = 0.5 * sh.height_m;
                (a * a * (1.0 - axz * axz) + c * c * axz * axz).sqrt()
            }
            None => a,
        };
        top = top.max(st.position.z + h);
        mean += st.position.z / last.len() as f64;
    }
    (top, mean, tilt)
}

/// 500 apples (D 75 +- 5 mm) poured into the 1.2 x 1.2 m bin, spheres against spheroids of
/// aspect 0.85 +- 0.05 turned at random (docs/lines.md section 3d): the spheroids' heap is
/// lower (highest top 0.2910 m against 0.3178 m, mean centre 0.0799 m against 0.0872 m), and they
/// come to rest with their axes nearer upright than at random (mean |axis . z| 0.595 against
/// 0.500 for uniform orientations; 0.322 of them within 37 degrees of upright, |axis . z| > 0.8,
/// against 0.2). Regression pins of these runs, held to the printed digits (re-pinned when
/// adaptive steps began to land on each source's emission; before: 0.2854 m against 0.3224 m,
/// 0.0781 m against 0.0865 m, 0.590, 0.336); the orientation
/// bias is also checked against the uniform distribution's own scatter (0.5 +- 3 sigma,
/// sigma = sqrt(1/12 / 500) = 0.0129).
#[test]
fn a_bin_of_spheroids_against_a_bin_of_spheres() {
    // The two fills side by side, each on a pool of its own thread (the suite's longest test;
    // a run's results do not depend on its thread count).
    let alone = |rel: &'static str| {
        move || {
            rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .expect("a thread pool")
                .install(|| heap(rel))
        }
    };
    let ((top_s, mean_s, _), (top_o, mean_o, tilt)) = std::thread::scope(|s| {
        let spheres = s.spawn(alone("scenarios/lines/bin_fill_500_spheres.json"));
        let spheroids = alone("scenarios/lines/bin_fill_500_spheroids.json")();
        (spheres.join().expect("the spheres' run"), spheroids)
    });
    let n = tilt.len() as f64;
    let m = tilt.iter().sum::<f64>() / n;
    let upright = tilt.iter().filter(|&&x| x > 0.8).count() as f64 / n;
    println!(
        "spheres: top {top_s:.4} m, mean centre {mean_s:.4} m; spheroids: top {top_o:.4} m, mean centre {mean_o:.4} m, mean |axis.z| {m:.3}, upright {upright:.3}"
    );
    assert_eq!(tilt.len(), 500);
    assert!((top_s - 0.3178).abs() < 1e-4 && (mean_s - 0.0872).abs() < 1e-4);
    assert!((top_o - 0.2910).abs() < 1e-4 && (mean_o - 0.0799).abs() < 1e-4);
    assert!((m - 0.595).abs() < 1e-3 && (upright - 0.322).abs() < 1e-3);
    assert!(
        m > 0.5 + 3.0 * (1.0 / 12.0 / n).sqrt(),
        "biased towards upright"
    );
}

/// The slip/roll detector with a spheroid (issue 29: a spheroid rolls when it turns about its
/// true contact point). An elongated apple (D 80 mm, height 88 mm, 0.107 kg) lies on its side on
/// the steel plate of `slip_to_roll.json`, axis across the launch, launched at 0.5 m/s without
/// spin (mu 0.3). While it slides, friction mu m g slows it and spins it up about its own axis
/// through the lever l = a - u from its centre to its contact point, so it rolls from
/// t = v0 / (mu g (1 + m l^2 / I)), I = 2/5 m a^2 (the sphere's 2 v0 / (7 mu g) when u -> 0), at
/// v0 / (1 + I / (m l^2)). u is the resting sag under eq. 12 on the cheek (elliptic law,
/// R' = c^2 / a, R'' = a; at rest eq. 12 carries (1 + ke)/2 of Hertz). The detector's one
/// transition, sliding to rolling: 48.88908 ms against 48.88908 ms (7.0e-8) and 0.3561194 m/s
/// against 0.3561194 m/s (2.6e-8; docs/shape.md), held at twice those.
#[test]
fn a_spheroid_slides_then_rolls_on_its_side() {
    use applesim::contact::elliptic::elliptic_hertz;
    use applesim::record::transitions::Motion;
    let mut sc = shipped("scenarios/slip_to_roll.json");
    let (a, c, m, mu, g, v0, ke) = (0.04, 0.044, 0.107, 0.3, 9.81, 0.5, 0.09);
    // E* of the apple (G 1 MPa, nu 0.18) on steel (G 81 GPa, nu 0.28), as physics.md section 1.
    let e = |g_mod: f64, nu: f64| 2.0 * g_mod * (1.0 + nu);
    let e_star = 1.0
        / ((1.0 - 0.18f64.powi(2)) / e(1.0e6, 0.18) + (1.0 - 0.28f64.powi(2)) / e(8.1e10, 0.28));
    let r_k = elliptic_hertz(c * c / a, a).stiffness_radius_m;
    let k = 4.0 / 3.0 * e_star * r_k.sqrt();
    let u = (m * g / (0.5 * (1.0 + ke) * k)).powf(2.0 / 3.0);
    let l = a - u;
    let inertia = 0.4 * m * a * a;
    let t_closed = v0 / (mu * g * (1.0 + m * l * l / inertia));
    let v_closed = v0 / (1.0 + inertia / (m * l * l));
    let apple = &mut sc.apples[0];
    apple.height_m = Some(2.0 * c);
    apple.rotation =
        Some(serde_json::from_str(r#"{"axis": [1, 0, 0], "angle_deg": 90}"#).expect("a rotation"));
    apple.position_m = [0.0, 0.0, l];
    sc.duration_s = 0.12;
    let (r, _) = run(&sc);
    assert_eq!(r.transitions.len(), 1, "{:#?}", r.transitions);
    let tr = &r.transitions[0];
    println!(
        "t {} (closed {t_closed}, sphere 2 v0 / (7 mu g) = {}), speed {} (closed {v_closed}), u {u}",
        tr.time_s,
        2.0 * v0 / (7.0 * mu * g),
        tr.speed_m_s
    );
    assert_eq!((tr.from, tr.to), (Motion::Sliding, Motion::Rolling));
    assert!(
        (tr.time_s / t_closed - 1.0).abs() < 1.4e-7,
        "time {}",
        tr.time_s
    );
    assert!(
        (tr.speed_m_s / v_closed - 1.0).abs() < 5.2e-8,
        "speed {}",
        tr.speed_m_s
    );
}
