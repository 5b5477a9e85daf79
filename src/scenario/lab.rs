//! A drop-test lab's setup for `applesim calibrate-bruise` (docs/damage.md section 8): the
//! materials, the contact coefficients and the per-pair overrides, written as a scenario writes
//! them (copy them from one), and the test surfaces a drop may name, each a material with an
//! optional pad bonded on it. A drop naming a bare material strikes a flat of it.

use super::surfaces::PaddingSpec;
use super::{de, presets, ContactSpec, MaterialSpec, PairSpec, Scenario, ScenarioError};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The lab file (`applesim calibrate-bruise --materials FILE`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabSetup {
    /// Named materials: the apple's and every surface's (a scenario's `materials`).
    #[serde(deserialize_with = "de::unique_map")]
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Contact coefficients of every pair without a `pairs` entry (a scenario's `contact`).
    pub contact: ContactSpec,
    /// Per-pair overrides (a scenario's `pairs`).
    #[serde(default)]
    pub pairs: Vec<PairSpec>,
    /// Test surfaces by name, for drops onto a padded surface (a drop's `surface` names one of
    /// these or a material).
    #[serde(default, deserialize_with = "de::unique_map")]
    pub surfaces: BTreeMap<String, TestSurface>,
}

/// A test surface: a flat of `material`, with an optional pad bonded on it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TestSurface {
    /// The flat's material (the substrate under a pad).
    pub material: String,
    /// A pad bonded on it (docs/physics.md section 13).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub padding: Option<PaddingSpec>,
}

impl LabSetup {
    /// Parses a lab file's text (`file` names it in messages), with its material presets and
    /// their pair coefficients filled in as a scenario's are.
    pub fn from_json(text: &str, file: &str) -> Result<Self, ScenarioError> {
        let mut lab: LabSetup = super::parse_one(text, file)?;
        // The presets fill a scenario's materials and pairs: lend them one.
        let mut sc = Scenario {
            description: None,
            duration_s: 1.0,
            time_step_s: 1e-5.into(),
            accuracy: None,
            max_time_step_s: None,
            fidelity: Default::default(),
            gravity_m_s2: [0.0; 3],
            output: Default::default(),
            materials: std::mem::take(&mut lab.materials),
            contact: lab.contact,
            pairs: std::mem::take(&mut lab.pairs),
            model: Default::default(),
            apples: Vec::new(),
            generators: Vec::new(),
            sources: Vec::new(),
            surfaces: Vec::new(),
            grading: None,
        };
        presets::resolve(&mut sc)?;
        lab.materials = sc.materials;
        lab.pairs = sc.pairs;
        for (name, s) in &lab.surfaces {
            let known = |m: &str| lab.materials.contains_key(m);
            if !known(&s.material) {
                return Err(ScenarioError::invalid(
                    format!("surfaces.{name}.material"),
                    format!(
                        "unknown material '{}' (defined: {})",
                        s.material,
                        lab.material_names()
                    ),
                ));
            }
            if let Some(p) = &s.padding {
                if !known(&p.material) {
                    return Err(ScenarioError::invalid(
                        format!("surfaces.{name}.padding.material"),
                        format!(
                            "unknown material '{}' (defined: {})",
                            p.material,
                            lab.material_names()
                        ),
                    ));
                }
            }
        }
        Ok(lab)
    }

    /// Reads and parses a lab file.
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json(&text, &path.display().to_string())
    }

    /// The materials' names, comma-separated (for messages).
    pub fn material_names(&self) -> String {
        self.materials
            .keys()
            .cloned()
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The test surface a drop names: a surface of `surfaces`, else a bare flat of a material.
    pub fn surface(&self, name: &str) -> Option<TestSurface> {
        self.surfaces.get(name).cloned().or_else(|| {
            self.materials.contains_key(name).then(|| TestSurface {
                material: name.to_string(),
                padding: None,
            })
        })
    }

    /// The names a drop's `surface` may take, comma-separated (for messages).
    pub fn surface_names(&self) -> String {
        let mut names: Vec<&str> = self.surfaces.keys().map(String::as_str).collect();
        names.extend(
            self.materials
                .keys()
                .map(String::as_str)
                .filter(|m| !self.surfaces.contains_key(*m)),
        );
        names.join(", ")
    }
}
