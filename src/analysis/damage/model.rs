//! The damage models (docs/damage.md section 2): one hit of an apple in, its bruise out. Pure
//! functions of the contact's figures, each checked against its closed form.
//!
//! - **energy** (bruise-models.md M1): V = BS max(0, E - E_th), E the energy the apple absorbs in
//!   the hit (its share of the contact's loss, `contact::share`). Its shape: the full bruise of
//!   the hit is the spherical cap as wide as the contact over the width ratio and as deep as the
//!   depth ratio times the apple's own deformation (Stropek & Golacki, pears: the contact about
//!   1.4 times as wide as the bruise, the bruise about 2.5 times as deep as the deformation); a
//!   smaller volume is that cap scaled down, a larger one keeps its width and goes deeper
//!   ([`geometry::shaped_cap`], \[INF\]).
//! - **pressure-area** (M6): the part of the Hertz patch where the pressure p0 sqrt(1 - r^2/a^2)
//!   exceeds p_c is bruised, area pi a^2 (1 - (p_c/p0)^2); depth the depth ratio times the apple's
//!   own deformation at the peak (Stropek & Golacki: about 2.5 times), volume that of the cap.
//! - **peak-force** (M5, the paper's criterion): bruised when the peak force exceeds F_th. An
//!   onset model: it says nothing of the bruise's size.

use super::geometry;
use crate::scenario::damage::{
    self as spec, DamageModelName, DamageSpec, Validity, DEFAULT_PRESET,
};

/// A damage model with its coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Model {
    /// Bruise volume linear in the absorbed energy above a threshold.
    Energy {
        /// Bruise susceptibility (mm^3 per J absorbed).
        bs_mm3_per_j: f64,
        /// Threshold energy (J).
        threshold_j: f64,
    },
    /// The Hertz patch above a critical pressure is bruised.
    PressureArea {
        /// Critical pressure (Pa).
        critical_pa: f64,
    },
    /// Bruised above a peak force (no size).
    PeakForce {
        /// Threshold force (N).
        threshold_n: f64,
    },
}

impl Model {
    /// The model's name (`energy`, `pressure-area`, `peak-force`).
    pub fn name(&self) -> &'static str {
        match self {
            Model::Energy { .. } => DamageModelName::Energy.as_str(),
            Model::PressureArea { .. } => DamageModelName::PressureArea.as_str(),
            Model::PeakForce { .. } => DamageModelName::PeakForce.as_str(),
        }
    }

    /// Whether the model gives bruise sizes (the peak-force model gives onset only).
    pub fn sizes(&self) -> bool {
        !matches!(self, Model::PeakForce { .. })
    }
}

/// The damage model of one apple material, resolved from its scenario entry and preset.
#[derive(Debug, Clone, PartialEq)]
pub struct DamageParams {
    /// The model.
    pub model: Model,
    /// Weight of the hits after the hardest at one site (repeat rule, [`super::sites`]).
    pub repeat_weight: f64,
    /// Contact width over bruise width.
    pub width_ratio: f64,
    /// Bruise depth over the apple's deformation (pressure-area model).
    pub depth_ratio: f64,
    /// Static force threshold of resting contacts (N), if set.
    pub static_force_n: Option<f64>,
    /// Static mean-pressure threshold of resting contacts (Pa), if set.
    pub static_pressure_pa: Option<f64>,
    /// Where the model was measured (outside: a warning).
    pub validity: Validity,
    /// The preset the values start from.
    pub preset: &'static str,
    /// Where the entry's own values come from (a calibration file), if said.
    pub source: Option<String>,
}

impl DamageParams {
    /// The model of a material's `damage` entry (`None`: the default preset). The entry was
    /// validated ([`spec::validate`]): its model has its coefficients.
    pub fn of(entry: Option<&DamageSpec>) -> Self {
        let empty = DamageSpec::default();
        let d = entry.unwrap_or(&empty);
        let preset = d
            .preset
            .as_deref()
            .and_then(spec::damage_preset)
            .or_else(|| spec::damage_preset(DEFAULT_PRESET))
            .expect("the default preset is in the table");
        let name = d.model.unwrap_or(preset.model);
        // A preset's coefficient serves only its own model.
        let from_preset = |x: Option<spec::Sourced>| {
            if name == preset.model {
                x.map(|s| s.value)
            } else {
                None
            }
        };
        let pick =
            |own: Option<f64>, p: Option<spec::Sourced>| own.or(from_preset(p)).unwrap_or(f64::NAN);
        let model = match name {
            DamageModelName::Energy => Model::Energy {
                bs_mm3_per_j: pick(
                    d.bruise_susceptibility_mm3_j,
                    preset.bruise_susceptibility_mm3_j,
                ),
                threshold_j: pick(d.threshold_energy_j, preset.threshold_energy_j),
            },
            DamageModelName::PressureArea => Model::PressureArea {
                critical_pa: pick(d.critical_pressure_pa, preset.critical_pressure_pa),
            },
            DamageModelName::PeakForce => Model::PeakForce {
                threshold_n: pick(d.peak_force_n, preset.peak_force_n),
            },
        };
        let validity = if name == preset.model {
            preset.validity
        } else {
            Validity {
                max_energy_j: None,
                max_force_n: None,
                rigid_surfaces_only: false,
                text: "the user's own coefficients: no range known",
            }
        };
        DamageParams {
            model,
            repeat_weight: d.repeat_weight.unwrap_or(spec::REPEAT_WEIGHT.value),
            width_ratio: d.width_ratio.unwrap_or(spec::WIDTH_RATIO.value),
            depth_ratio: d.depth_ratio.unwrap_or(spec::DEPTH_RATIO.value),
            static_force_n: d.static_force_n,
            static_pressure_pa: d.static_pressure_pa,
            validity,
            preset: preset.name,
            source: d.source.clone(),
        }
    }
}

/// What an apple went through in one hit (its side of one impact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Energy the apple absorbed (J): its share of the impact's loss.
    pub absorbed_energy_j: f64,
    /// Peak normal force (N).
    pub peak_force_n: f64,
    /// Peak centre pressure p0 = 1.5 P / (pi a^2) (Pa).
    pub peak_pressure_pa: f64,
    /// Largest contact radius (m).
    pub contact_radius_m: f64,
    /// The apple's own deformation at the peak (m).
    pub indentation_m: f64,
    /// The apple's share of the contact's deformation (1 on a rigid surface).
    pub stored_share: f64,
}

/// The bruise one hit would make on its own.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HitDamage {
    /// Whether the hit bruises (above the model's onset).
    pub bruised: bool,
    /// What the repeat rule adds up at a site: the absorbed energy (energy model) or the bruise
    /// volume (pressure-area, mm^3); 0 for the peak-force model.
    pub dose: f64,
    /// Bruise volume (mm^3; `None` for the peak-force model).
    pub volume_mm3: Option<f64>,
    /// Bruise surface diameter (mm).
    pub diameter_mm: Option<f64>,
    /// Bruise depth (mm).
    pub depth_mm: Option<f64>,
}

/// The bruise of one hit alone.
pub fn evaluate(p: &DamageParams, h: &Hit) -> HitDamage {
    match p.model {
        Model::Energy {
            bs_mm3_per_j,
            threshold_j,
        } => {
            let v = energy_volume(bs_mm3_per_j, threshold_j, h.absorbed_energy_j);
            let (d, depth) = geometry::shaped_cap(v, full_width_mm(p, h), full_depth_mm(p, h));
            HitDamage {
                bruised: h.absorbed_energy_j > threshold_j,
                dose: h.absorbed_energy_j,
                volume_mm3: Some(v),
                diameter_mm: Some(d),
                depth_mm: Some(depth),
            }
        }
        Model::PressureArea { critical_pa } => {
            let area = geometry::area_above_pressure(
                1e3 * h.contact_radius_m,
                h.peak_pressure_pa,
                critical_pa,
            );
            let d = geometry::disc_diameter(area);
            let depth = if area > 0.0 { full_depth_mm(p, h) } else { 0.0 };
            let v = geometry::cap_volume(d, depth);
            HitDamage {
                bruised: area > 0.0,
                dose: v,
                volume_mm3: Some(v),
                diameter_mm: Some(d),
                depth_mm: Some(depth),
            }
        }
        Model::PeakForce { threshold_n } => HitDamage {
            bruised: h.peak_force_n > threshold_n,
            ..HitDamage::default()
        },
    }
}

/// The width of a hit's full bruise (mm): the contact diameter over the width ratio.
pub fn full_width_mm(p: &DamageParams, h: &Hit) -> f64 {
    2e3 * h.contact_radius_m / p.width_ratio
}

/// The depth of a hit's full bruise (mm): the depth ratio times the apple's own deformation.
pub fn full_depth_mm(p: &DamageParams, h: &Hit) -> f64 {
    1e3 * p.depth_ratio * h.indentation_m
}

/// The energy model's volume (mm^3): BS max(0, E - E_th).
pub fn energy_volume(bs_mm3_per_j: f64, threshold_j: f64, e_j: f64) -> f64 {
    bs_mm3_per_j * (e_j - threshold_j).max(0.0)
}

/// Why a hit lies outside the model's validity, if it does.
pub fn outside_validity(p: &DamageParams, h: &Hit) -> Option<&'static str> {
    let v = &p.validity;
    if v.max_energy_j.is_some_and(|m| h.absorbed_energy_j > m) {
        return Some("absorbed energy above the range the model was measured in");
    }
    if v.max_force_n.is_some_and(|m| h.peak_force_n > m) {
        return Some("peak force above the range the model was measured in");
    }
    if v.rigid_surfaces_only && h.stored_share < spec::RIGID_SHARE {
        return Some("a soft partner: the model was measured on hard surfaces only");
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(e: f64) -> Hit {
        Hit {
            absorbed_energy_j: e,
            peak_force_n: 60.0,
            peak_pressure_pa: 3e5,
            contact_radius_m: 6e-3,
            indentation_m: 2e-3,
            stored_share: 1.0,
        }
    }

    #[test]
    fn energy_model_is_linear_above_its_threshold() {
        let p = DamageParams::of(None);
        let Model::Energy {
            bs_mm3_per_j,
            threshold_j,
        } = p.model
        else {
            panic!("the default is the energy model")
        };
        assert_eq!((bs_mm3_per_j, threshold_j), (4700.0, 0.08));
        let below = evaluate(&p, &hit(0.079));
        assert!(!below.bruised && below.volume_mm3 == Some(0.0) && below.depth_mm == Some(0.0));
        let d = evaluate(&p, &hit(0.2));
        assert!(d.bruised);
        assert!((d.volume_mm3.unwrap() - 4700.0 * 0.12).abs() < 1e-9);
        // The full bruise: the contact's 12 mm over 1.4 wide, 2.5 x 2 mm deep (a cap of
        // 365.6 mm^3); 564 mm^3 is more: as wide, deeper.
        let dia = 12.0 / 1.4;
        assert!((d.diameter_mm.unwrap() - dia).abs() < 1e-12);
        assert!(d.depth_mm.unwrap() > 5.0);
        let v = geometry::cap_volume(dia, d.depth_mm.unwrap());
        assert!((v / 564.0 - 1.0).abs() < 1e-12);
        // A small bruise is the full cap scaled down: 36.56 mm^3 is a tenth, (0.1)^(1/3).
        let full = geometry::cap_volume(dia, 5.0);
        let small = evaluate(&p, &hit(0.08 + 0.1 * full / 4700.0));
        let k = 0.1f64.cbrt();
        assert!((small.diameter_mm.unwrap() - dia * k).abs() < 1e-9);
        assert!((small.depth_mm.unwrap() - 5.0 * k).abs() < 1e-9);
    }

    #[test]
    fn pressure_area_model_bruises_the_patch_above_the_critical_pressure() {
        let p = DamageParams::of(Some(&DamageSpec {
            preset: Some("flesh-pressure".into()),
            ..Default::default()
        }));
        // p0 = 2 p_c: 3/4 of the 6 mm patch, depth 2.5 x 2 mm.
        let h = Hit {
            peak_pressure_pa: 5.8e5,
            ..hit(0.1)
        };
        let d = evaluate(&p, &h);
        let area = 0.75 * std::f64::consts::PI * 36.0;
        assert!(
            (d.diameter_mm.unwrap() - 2.0 * (area / std::f64::consts::PI).sqrt()).abs() < 1e-12
        );
        assert!((d.depth_mm.unwrap() - 5.0).abs() < 1e-12);
        assert!(d.bruised);
        let below = evaluate(
            &p,
            &Hit {
                peak_pressure_pa: 2.8e5,
                ..h
            },
        );
        assert!(!below.bruised && below.volume_mm3 == Some(0.0));
    }

    #[test]
    fn peak_force_model_gives_onset_only_and_warns_on_soft_partners() {
        let p = DamageParams::of(Some(&DamageSpec {
            preset: Some("jazz".into()),
            ..Default::default()
        }));
        assert!(evaluate(&p, &hit(0.0)).bruised);
        assert_eq!(evaluate(&p, &hit(0.0)).volume_mm3, None);
        let soft = Hit {
            stored_share: 0.5,
            ..hit(0.0)
        };
        assert!(outside_validity(&p, &soft).is_some());
        assert!(outside_validity(&p, &hit(0.0)).is_none());
    }

    #[test]
    fn entries_override_the_preset() {
        let p = DamageParams::of(Some(&DamageSpec {
            preset: Some("golshahi".into()),
            threshold_energy_j: Some(0.05),
            ..Default::default()
        }));
        assert_eq!(
            p.model,
            Model::Energy {
                bs_mm3_per_j: 5290.0,
                threshold_j: 0.05
            }
        );
        assert_eq!(p.repeat_weight, 0.7);
    }
}
