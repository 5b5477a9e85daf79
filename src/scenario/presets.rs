//! Material presets: a small table of materials and pair coefficients a scenario can name
//! (`"materials": {"fruit": {"preset": "apple-paper"}}`), each value with its source, and only
//! where a source gives it (docs/materials.md). A scenario's own numbers override a preset's;
//! a value no source gives must be written in the scenario (the refusal names it).
//!
//! Pair coefficients apply when both materials of a pair name presets the table has a pair for:
//! they fill the pair's `friction`, `rolling_friction` and restitution (for the eq. 12 dampings
//! ke = e^2, the limit lambda v0 >> 1 of physics.md section 3, with lambda 1000 s/m; for the
//! viscoelastic damping the restitution itself), unless the scenario's `pairs[]` entry for those
//! materials gives them.

use super::{models::Damping, MaterialSpec, PairSpec, Scenario, ScenarioError};

/// A material of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialPreset {
    /// The name a scenario uses.
    pub name: &'static str,
    /// Shear modulus (Pa), if the source gives it.
    pub shear_modulus_pa: Option<f64>,
    /// Young's modulus (Pa), if the source gives it.
    pub youngs_modulus_pa: Option<f64>,
    /// Poisson's ratio, if the source gives it.
    pub poisson_ratio: Option<f64>,
    /// Density (kg/m^3), if the source gives it.
    pub density_kg_m3: Option<f64>,
    /// Where the values come from.
    pub source: &'static str,
}

/// Coefficients of a pair of presets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairPreset {
    /// The two presets (either order).
    pub materials: [&'static str; 2],
    /// Coefficient of restitution, if the source gives it.
    pub restitution: Option<f64>,
    /// Static friction coefficient, if the source gives it.
    pub friction: Option<f64>,
    /// Coefficient of rolling friction, if the source gives it.
    pub rolling_friction: Option<f64>,
    /// Where the values come from.
    pub source: &'static str,
}

const LULI: &str = "DEM calibration of 'Luli' apples (2024), as quoted in applesim issue 19";
const EUROCODE: &str =
    "EN 1993-1-1 (Eurocode 3) 3.2.6: E = 210 000 N/mm^2, nu = 0.3; EN 1991-1-1 annex A: 78.5 kN/m^3";

/// The materials.
pub const MATERIALS: &[MaterialPreset] = &[
    MaterialPreset {
        name: "apple-paper",
        shear_modulus_pa: Some(1.1e6),
        youngs_modulus_pa: None,
        poisson_ratio: Some(0.18),
        density_kg_m3: Some(800.0),
        source: "the paper's Fig. 1 apple (G1 = 1.1 MPa in its text, nu1 = 0.18); density 800 kg/m^3, docs/physics.md section 8",
    },
    MaterialPreset {
        name: "apple-luli",
        shear_modulus_pa: None,
        youngs_modulus_pa: None,
        poisson_ratio: None,
        density_kg_m3: None,
        source: "the calibration gives contact coefficients only (see the pairs): give the modulus, Poisson's ratio and density",
    },
    MaterialPreset {
        name: "steel",
        shear_modulus_pa: None,
        youngs_modulus_pa: Some(2.1e11),
        poisson_ratio: Some(0.3),
        density_kg_m3: Some(7850.0),
        source: EUROCODE,
    },
    MaterialPreset {
        name: "steel-paper",
        shear_modulus_pa: Some(8.1e10),
        youngs_modulus_pa: None,
        poisson_ratio: Some(0.28),
        density_kg_m3: None,
        source: "the paper's steel plate (Fig. 1: G2 = 8.1e10 Pa, nu2 = 0.28)",
    },
    MaterialPreset {
        name: "plastic-paper",
        shear_modulus_pa: Some(1e9),
        youngs_modulus_pa: None,
        poisson_ratio: Some(0.3),
        density_kg_m3: None,
        source: "the paper's plastic container bottom (Fig. 5: G2 = 1e9 Pa, nu2 = 0.3)",
    },
    MaterialPreset {
        name: "wood-paper",
        shear_modulus_pa: Some(4e9),
        youngs_modulus_pa: None,
        poisson_ratio: None,
        density_kg_m3: None,
        source: "the paper's wooden platform (Fig. 4: G2 = 4e9 Pa; it gives no Poisson's ratio: give one)",
    },
    MaterialPreset {
        name: "foam-hd",
        shear_modulus_pa: None,
        youngs_modulus_pa: None,
        poisson_ratio: None,
        density_kg_m3: None,
        source: "high-density padding foam of the Luli calibration: contact coefficients only (see the pairs); give its modulus and Poisson's ratio",
    },
    MaterialPreset {
        name: "foam-shd",
        shear_modulus_pa: None,
        youngs_modulus_pa: None,
        poisson_ratio: None,
        density_kg_m3: None,
        source: "super-high-density padding foam of the Luli calibration: contact coefficients only (see the pairs); give its modulus and Poisson's ratio",
    },
];

/// The pairs.
pub const PAIRS: &[PairPreset] = &[
    PairPreset {
        materials: ["apple-luli", "apple-luli"],
        restitution: Some(0.65),
        friction: Some(0.42),
        rolling_friction: Some(0.032),
        source: LULI,
    },
    PairPreset {
        materials: ["apple-luli", "foam-hd"],
        restitution: Some(0.47),
        friction: Some(0.61),
        rolling_friction: Some(0.0288),
        source: LULI,
    },
    PairPreset {
        materials: ["apple-luli", "foam-shd"],
        restitution: Some(0.61),
        friction: Some(0.46),
        rolling_friction: Some(0.0166),
        source: LULI,
    },
    PairPreset {
        materials: ["apple-paper", "steel-paper"],
        restitution: None,
        friction: Some(0.3),
        rolling_friction: None,
        source: "docs/physics.md section 8: the least friction with which every Fig. 6-7 case rolls within 0.1 s, as the paper says",
    },
];

/// The preset of a name.
pub fn material(name: &str) -> Option<&'static MaterialPreset> {
    MATERIALS.iter().find(|p| p.name == name)
}

/// The pair coefficients of two presets (either order).
pub fn pair(a: &str, b: &str) -> Option<&'static PairPreset> {
    PAIRS
        .iter()
        .find(|p| (p.materials == [a, b]) || (p.materials == [b, a]))
}

/// Fills the materials that name a preset with its values (the scenario's own win), then adds
/// or completes the pairs of presets the table has coefficients for.
pub fn resolve(sc: &mut Scenario) -> Result<(), ScenarioError> {
    for (name, m) in sc.materials.iter_mut() {
        let Some(p) = m.preset.as_deref() else {
            continue;
        };
        let preset = material(p).ok_or_else(|| {
            ScenarioError::invalid(
                format!("materials.{name}.preset"),
                format!(
                    "unknown preset '{p}' (known: {})",
                    MATERIALS
                        .iter()
                        .map(|m| m.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })?;
        fill(m, preset);
    }
    let named: Vec<(String, String)> = sc
        .materials
        .iter()
        .filter_map(|(n, m)| m.preset.clone().map(|p| (n.clone(), p)))
        .collect();
    for (i, (na, pa)) in named.iter().enumerate() {
        for (nb, pb) in &named[i..] {
            let Some(pp) = pair(pa, pb) else { continue };
            let existing = sc.pairs.iter_mut().find(|q| {
                (q.materials[0] == *na && q.materials[1] == *nb)
                    || (q.materials[0] == *nb && q.materials[1] == *na)
            });
            let entry = match existing {
                Some(e) => e,
                None => {
                    sc.pairs.push(PairSpec {
                        materials: [na.clone(), nb.clone()],
                        friction: None,
                        ke: None,
                        lambda_s_m: None,
                        damping: None,
                        restitution: None,
                        tangential: None,
                        rolling: None,
                        rolling_friction: None,
                        rolling_damping: None,
                        twisting: None,
                    });
                    sc.pairs.last_mut().expect("just pushed")
                }
            };
            let damping = entry.damping.unwrap_or(sc.contact.damping);
            entry.friction = entry.friction.or(pp.friction);
            entry.rolling_friction = entry.rolling_friction.or(pp.rolling_friction);
            if let Some(e) = pp.restitution {
                match damping {
                    Damping::Viscoelastic => entry.restitution = entry.restitution.or(Some(e)),
                    Damping::Eq12 | Damping::Eq12ElasticRest => {
                        if entry.ke.is_none() {
                            entry.ke = Some(e * e);
                            entry.lambda_s_m = entry.lambda_s_m.or(Some(1000.0));
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

fn fill(m: &mut MaterialSpec, p: &MaterialPreset) {
    // A modulus given in the scenario replaces the preset's (either kind).
    if m.shear_modulus_pa.is_none() && m.youngs_modulus_pa.is_none() {
        m.shear_modulus_pa = p.shear_modulus_pa;
        m.youngs_modulus_pa = p.youngs_modulus_pa;
    }
    m.poisson_ratio = m.poisson_ratio.or(p.poisson_ratio);
    m.density_kg_m3 = m.density_kg_m3.or(p.density_kg_m3);
}

/// The table as Markdown (docs/materials.md has the same tables; a test keeps them equal).
pub fn markdown() -> String {
    let v = |x: Option<f64>| match x {
        None => "-".to_string(),
        Some(x) if (1e-3..1e4).contains(&x.abs()) => format!("{x}"),
        Some(x) => format!("{x:e}"),
    };
    let mut s = String::from(
        "| preset | G (Pa) | E (Pa) | nu | density (kg/m^3) | source |\n|---|---|---|---|---|---|\n",
    );
    for p in MATERIALS {
        s += &format!(
            "| `{}` | {} | {} | {} | {} | {} |\n",
            p.name,
            v(p.shear_modulus_pa),
            v(p.youngs_modulus_pa),
            v(p.poisson_ratio),
            v(p.density_kg_m3),
            p.source
        );
    }
    s += "\n| pair | restitution | friction | rolling friction | source |\n|---|---|---|---|---|\n";
    for p in PAIRS {
        s += &format!(
            "| `{}` - `{}` | {} | {} | {} | {} |\n",
            p.materials[0],
            p.materials[1],
            v(p.restitution),
            v(p.friction),
            v(p.rolling_friction),
            p.source
        );
    }
    s
}
