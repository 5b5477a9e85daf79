//! Bruises on the apple: each hit lands at a site of the apple's own surface, and repeated hits
//! at one site make one bruise that grows by less than each hit alone (docs/damage.md section 4).
//!
//! A hit is placed by the unit vector from the apple's centre to the contact point at the peak
//! force, in the apple's own frame (`record::events::ImpactPulse::sites`): the same spot of the
//! fruit whatever the apple did in between. A hit joins a site when the arc between them, R theta,
//! is at most the larger contact radius of the two (a site is a patch of about one contact
//! radius, bruise-models.md M10); the site keeps the place of its first hit.
//!
//! Repeated hits (M10 \[INF\]): the hits of a site, hardest first, count with weights 1, beta,
//! beta^2, ... (beta the repeat weight): the energy model adds energies, E_eq = sum_k beta^k E_(k),
//! and bruises BS max(0, E_eq - E_th), so several hits below the threshold can bruise together;
//! the pressure-area model adds volumes the same way. Equal hits then add less and less and the
//! bruise stops growing at 1/(1 - beta) times one hit's dose, as the pendulum studies report
//! (each repeat adds less, the bruise stabilises after about five hits \[R-abs\]); n hits bruise
//! less than one hit of their summed energy. The site's full bruise is as wide and as deep as
//! its widest and deepest hit's, and its volume shapes it (`geometry::shaped_cap`).

use super::geometry;
use super::model::{DamageParams, HitDamage, Model};

/// One hit as the site rule sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacedHit {
    /// Unit vector from the apple's centre to the hit, in the apple's own frame.
    pub direction: [f64; 3],
    /// Largest contact radius of the hit (m).
    pub contact_radius_m: f64,
    /// The hit's own bruise ([`super::model::evaluate`]).
    pub damage: HitDamage,
    /// Energy the apple absorbed in the hit (J).
    pub absorbed_energy_j: f64,
    /// The hit's full bruise width and depth (mm; [`super::model::full_width_mm`],
    /// [`super::model::full_depth_mm`]).
    pub full_width_mm: f64,
    /// See `full_width_mm`.
    pub full_depth_mm: f64,
}

/// One bruise site of an apple.
#[derive(Debug, Clone, PartialEq)]
pub struct Site {
    /// Where, in the apple's frame (unit vector; its first hit's).
    pub direction: [f64; 3],
    /// The hits there (indices into the apple's hits, in order).
    pub hits: Vec<usize>,
    /// Energy the apple absorbed there, all hits (J).
    pub absorbed_energy_j: f64,
    /// Whether the site is bruised.
    pub bruised: bool,
    /// Bruise volume (mm^3; `None` for an onset model).
    pub volume_mm3: Option<f64>,
    /// Surface diameter (mm).
    pub diameter_mm: Option<f64>,
    /// Depth (mm).
    pub depth_mm: Option<f64>,
    /// Each hit's part of the volume, in the order of `hits` (its weight in the repeat rule over
    /// the sum of the weights; the parts add up to the volume).
    pub parts_mm3: Vec<f64>,
    /// The largest contact radius of its hits (m): the site's reach.
    pub reach_m: f64,
}

impl Site {
    /// Surface area of the bruise (mm^2): the disc of its diameter.
    pub fn area_mm2(&self) -> Option<f64> {
        self.diameter_mm.map(|d| std::f64::consts::PI * d * d / 4.0)
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The sites of an apple of radius `radius_m` from its hits in order of time.
pub fn sites(p: &DamageParams, radius_m: f64, hits: &[PlacedHit]) -> Vec<Site> {
    let mut out: Vec<Site> = Vec::new();
    for (k, h) in hits.iter().enumerate() {
        let found = out.iter().position(|s| {
            let cos = dot(s.direction, h.direction).clamp(-1.0, 1.0);
            radius_m * cos.acos() <= s.reach_m.max(h.contact_radius_m)
        });
        match found {
            Some(i) => {
                let s = &mut out[i];
                s.hits.push(k);
                s.reach_m = s.reach_m.max(h.contact_radius_m);
            }
            None => out.push(Site {
                direction: h.direction,
                hits: vec![k],
                absorbed_energy_j: 0.0,
                bruised: false,
                volume_mm3: None,
                diameter_mm: None,
                depth_mm: None,
                parts_mm3: Vec::new(),
                reach_m: h.contact_radius_m,
            }),
        }
    }
    for s in &mut out {
        let at: Vec<&PlacedHit> = s.hits.iter().map(|&k| &hits[k]).collect();
        settle(p, s, &at);
    }
    out
}

/// The bruise of a site from its hits (the repeat rule).
fn settle(p: &DamageParams, s: &mut Site, hits: &[&PlacedHit]) {
    s.absorbed_energy_j = hits.iter().map(|h| h.absorbed_energy_j).sum();
    // Weights of the repeat rule: hardest first (earlier first among equals), beta^rank.
    let doses: Vec<f64> = hits.iter().map(|h| h.damage.dose).collect();
    let mut order: Vec<usize> = (0..doses.len()).collect();
    order.sort_by(|&a, &b| doses[b].total_cmp(&doses[a]).then(a.cmp(&b)));
    let mut weights = vec![0.0; doses.len()];
    let mut w = 1.0;
    for k in order {
        weights[k] = w * doses[k];
        w *= p.repeat_weight;
    }
    let equivalent: f64 = weights.iter().sum();
    let widest = hits
        .iter()
        .filter_map(|h| h.damage.diameter_mm)
        .fold(0.0, f64::max);
    match p.model {
        Model::Energy {
            bs_mm3_per_j,
            threshold_j,
        } => {
            let v = super::model::energy_volume(bs_mm3_per_j, threshold_j, equivalent);
            // The full bruise of the site: the widest and deepest its hits make (a hit below
            // the threshold still presses its patch); the volume shapes it (shaped_cap).
            let d0 = hits.iter().map(|h| h.full_width_mm).fold(0.0, f64::max);
            let h0 = hits.iter().map(|h| h.full_depth_mm).fold(0.0, f64::max);
            let (d, h) = geometry::shaped_cap(v, d0, h0);
            s.bruised = equivalent > threshold_j;
            s.volume_mm3 = Some(v);
            s.diameter_mm = Some(d);
            s.depth_mm = Some(h);
            s.parts_mm3 = split(v, &weights);
        }
        Model::PressureArea { .. } => {
            s.bruised = hits.iter().any(|h| h.damage.bruised);
            s.volume_mm3 = Some(equivalent);
            s.diameter_mm = Some(widest);
            s.depth_mm = Some(geometry::cap_depth(equivalent, widest));
            s.parts_mm3 = split(equivalent, &weights);
        }
        Model::PeakForce { .. } => {
            s.bruised = hits.iter().any(|h| h.damage.bruised);
            s.parts_mm3 = vec![0.0; hits.len()];
        }
    }
}

/// `v` split in proportion to `weights` (equal parts when they are all 0).
fn split(v: f64, weights: &[f64]) -> Vec<f64> {
    let sum: f64 = weights.iter().sum();
    if sum > 0.0 {
        weights.iter().map(|w| v * w / sum).collect()
    } else {
        vec![v / weights.len().max(1) as f64; weights.len()]
    }
}

#[cfg(test)]
mod tests {
    use super::super::model::{evaluate, Hit};
    use super::*;

    fn placed(p: &DamageParams, dir: [f64; 3], e: f64) -> PlacedHit {
        let h = Hit {
            absorbed_energy_j: e,
            peak_force_n: 50.0,
            peak_pressure_pa: 3e5,
            contact_radius_m: 6e-3,
            indentation_m: 2e-3,
            stored_share: 1.0,
        };
        PlacedHit {
            direction: dir,
            contact_radius_m: h.contact_radius_m,
            damage: evaluate(p, &h),
            absorbed_energy_j: e,
            full_width_mm: super::super::model::full_width_mm(p, &h),
            full_depth_mm: super::super::model::full_depth_mm(p, &h),
        }
    }

    #[test]
    fn repeated_hits_add_less_and_far_hits_make_their_own_site() {
        let p = DamageParams::of(None);
        let r = 0.04;
        // 6 mm patches: a hit 0.1 rad (4 mm of arc) away joins, one a quarter turn away does not.
        let near = [0.1f64.sin(), 0.0, 0.1f64.cos()];
        let hits = [
            placed(&p, [0.0, 0.0, 1.0], 0.2),
            placed(&p, near, 0.1),
            placed(&p, [1.0, 0.0, 0.0], 0.1),
        ];
        let s = sites(&p, r, &hits);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].hits, [0, 1]);
        // E_eq = 0.2 + 0.7 x 0.1 = 0.27 J: 4700 x 0.19 = 893 mm^3, less than one hit of 0.3 J
        // (1034 mm^3).
        let v = s[0].volume_mm3.unwrap();
        assert!((v - 4700.0 * (0.27 - 0.08)).abs() < 1e-9, "{v}");
        assert!(v < 4700.0 * (0.3 - 0.08));
        // The parts add up to the volume, in proportion 0.2 : 0.07.
        let parts = &s[0].parts_mm3;
        assert!((parts[0] + parts[1] - v).abs() < 1e-9);
        assert!((parts[0] / parts[1] - 0.2 / 0.07).abs() < 1e-9);
        assert!((s[0].absorbed_energy_j - 0.3).abs() < 1e-15);
        // The far hit alone: 4700 x 0.02.
        assert!((s[1].volume_mm3.unwrap() - 94.0).abs() < 1e-9);
    }

    #[test]
    fn hits_below_the_threshold_can_bruise_together() {
        let p = DamageParams::of(None);
        let hits: Vec<PlacedHit> = (0..5).map(|_| placed(&p, [0.0, 0.0, 1.0], 0.05)).collect();
        assert!(hits.iter().all(|h| !h.damage.bruised));
        let s = sites(&p, 0.04, &hits);
        assert_eq!(s.len(), 1);
        // 0.05 (1 + 0.7 + 0.7^2 + 0.7^3 + 0.7^4) = 0.05 x 2.7731 = 0.13866 J > 0.08 J.
        assert!(s[0].bruised);
        let e_eq = 0.05 * (1.0 - 0.7f64.powi(5)) / 0.3;
        assert!((s[0].volume_mm3.unwrap() - 4700.0 * (e_eq - 0.08)).abs() < 1e-9);
    }

    #[test]
    fn equal_repeats_saturate_at_one_over_one_minus_beta() {
        let p = DamageParams::of(None);
        let grow = |n: usize| {
            let hits: Vec<PlacedHit> = (0..n).map(|_| placed(&p, [0.0, 0.0, 1.0], 0.2)).collect();
            sites(&p, 0.04, &hits)[0].volume_mm3.unwrap()
        };
        // Increments fall: V(2) - V(1) > V(3) - V(2) > ...
        let v: Vec<f64> = (1..=6).map(grow).collect();
        for k in 2..v.len() {
            assert!(v[k] - v[k - 1] < v[k - 1] - v[k - 2]);
        }
        // Bounded by the geometric limit 0.2 / 0.3 J.
        let limit = 4700.0 * (0.2 / 0.3 - 0.08);
        assert!(grow(200) <= limit && grow(200) > 0.9999 * limit);
    }
}
