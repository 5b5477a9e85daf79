//! The roster: every apple of a run, resolved once when the world is built (name, material,
//! radius, mass, and where it came from), and carried in the run's result so that analysis,
//! calibration, the trade-off study and the validation read it instead of going back to the
//! scenario (whose generators would otherwise be expanded again, and its mass rule written again).

use crate::contact::spheroid::Spheroid;
use crate::scenario::{AppleSpec, Scenario, ScenarioError};
use serde::Serialize;
use std::collections::BTreeMap;

/// Where an apple came from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Origin {
    /// Listed in the scenario's `apples[index]`.
    Listed {
        /// Index in `apples`.
        index: usize,
    },
    /// Placed at the start by `generators[generator]`.
    Generated {
        /// Index in `generators`.
        generator: usize,
    },
    /// Fed in over time by `sources[source]`, planned at `time_s` (it enters later if its spot
    /// is still taken).
    Fed {
        /// Index in `sources`.
        source: usize,
        /// Planned time of entry (s).
        time_s: f64,
    },
}

impl Origin {
    /// The scenario field that made the apple: `apples[3]`, `generators[0]`, `sources[1]`.
    pub fn field(&self) -> String {
        match *self {
            Origin::Listed { index } => format!("apples[{index}]"),
            Origin::Generated { generator } => format!("generators[{generator}]"),
            Origin::Fed { source, .. } => format!("sources[{source}]"),
        }
    }
}

/// One apple of the roster.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RosterApple {
    /// Unique name.
    pub name: String,
    /// Material name.
    pub material: String,
    /// Radius (m): the equatorial one of a spheroid (half its `diameter_m`).
    pub radius_m: f64,
    /// Height along its own z axis (m) of a spheroid (issue 29); `None` for a sphere, whose
    /// height is its diameter (and whose roster reads as it always did).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub height_m: Option<f64>,
    /// Mass (kg): `mass_kg`, or the material's density times the volume of the solid sphere or
    /// spheroid ([`apple_mass`]).
    pub mass_kg: f64,
    /// Where it came from.
    pub origin: Origin,
    /// A virtual instrumented sphere (`apples[].probe`), not fruit: left out of every fruit
    /// figure (bruises, grades, the audit).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub probe: bool,
}

impl RosterApple {
    /// Its shape: a sphere of its radius, or its spheroid.
    pub fn spheroid(&self) -> Spheroid {
        Spheroid::new(
            self.radius_m,
            self.height_m.map_or(self.radius_m, |h| 0.5 * h),
        )
    }
}

/// Every apple the world holds, in the layer's order (`AppleId`): the listed ones, the generated
/// ones, then the fed-in ones in the order they entered.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Roster {
    apples: Vec<RosterApple>,
}

impl Roster {
    /// The apples, in the layer's order.
    pub fn apples(&self) -> &[RosterApple] {
        &self.apples
    }

    /// Number of apples.
    pub fn len(&self) -> usize {
        self.apples.len()
    }

    /// Whether the roster is empty.
    pub fn is_empty(&self) -> bool {
        self.apples.is_empty()
    }

    /// The apple named `name` (a linear search; use [`Self::by_name`] for many lookups).
    pub fn get(&self, name: &str) -> Option<&RosterApple> {
        self.apples.iter().find(|a| a.name == name)
    }

    /// The apples by name.
    pub fn by_name(&self) -> BTreeMap<&str, &RosterApple> {
        self.apples.iter().map(|a| (a.name.as_str(), a)).collect()
    }

    /// The roster a scenario's run will hold, resolved without building a world: its apples
    /// present at t = 0, then its planned feeds (in planned order; a run lists fed-in apples in the
    /// order they entered). For readers of a finished run's folder, which keeps no roster.
    pub fn resolve(sc: &Scenario) -> Result<Self, ScenarioError> {
        let p = plan(sc)?;
        let density = |m: &str| sc.materials.get(m).and_then(|m| m.density_kg_m3);
        let mut r = Self::default();
        for (a, origin) in &p.initial {
            r.push(entry(a, density(&a.material), *origin));
        }
        for (t, k, a) in &p.feeds {
            let origin = Origin::Fed {
                source: *k,
                time_s: *t,
            };
            r.push(entry(a, density(&a.material), origin));
        }
        Ok(r)
    }

    pub(super) fn push(&mut self, apple: RosterApple) {
        self.apples.push(apple);
    }
}

/// Mass of a solid sphere of the given diameter and density (kg).
pub fn sphere_mass(diameter_m: f64, density: f64) -> f64 {
    let r = diameter_m / 2.0;
    density * 4.0 / 3.0 * std::f64::consts::PI * r * r * r
}

/// The mass of an apple (kg): its `mass_kg`, else its material's density times the volume of a
/// solid sphere of its diameter, or of a spheroid (4/3 pi a^2 c) of its diameter and height (0
/// when the material has no density: validation refuses that before a world is built). With
/// `mass_kg` given, a spheroid's density is what its volume makes of it. The one place this
/// rule is written.
pub fn apple_mass(spec: &AppleSpec, density_kg_m3: Option<f64>) -> f64 {
    spec.mass_kg.unwrap_or_else(|| {
        let rho = density_kg_m3.unwrap_or(0.0);
        if spec.is_spheroid() {
            rho * spec.spheroid().volume_m3()
        } else {
            sphere_mass(spec.diameter_m, rho)
        }
    })
}

/// The roster entry of an apple spec whose material has the density `density_kg_m3`.
pub fn entry(spec: &AppleSpec, density_kg_m3: Option<f64>, origin: Origin) -> RosterApple {
    RosterApple {
        name: spec.name.clone(),
        material: spec.material.clone(),
        radius_m: spec.diameter_m / 2.0,
        height_m: spec.height_m.filter(|_| spec.is_spheroid()),
        mass_kg: apple_mass(spec, density_kg_m3),
        origin,
        probe: spec.probe.is_some(),
    }
}

/// The apples of a scenario, resolved once: those present at t = 0 (listed, then each
/// generator's, with their origins), and the sources' planned feeds in order of time (then
/// source).
#[derive(Debug, Clone)]
pub struct Plan {
    /// Apples present at t = 0 and where they came from.
    pub initial: Vec<(AppleSpec, Origin)>,
    /// Planned feeds: (time, source index, apple placed where its source is at rest; a moving
    /// source carries it to where the source is when it appears).
    pub feeds: Vec<(f64, usize, AppleSpec)>,
}

/// Resolves the apples of a scenario (expands its generators and sources once).
pub fn plan(sc: &Scenario) -> Result<Plan, ScenarioError> {
    // The listed apples, then each generator's (a random fill avoids those already placed).
    let mut all = sc.apples.clone();
    let mut origins: Vec<Origin> = (0..all.len())
        .map(|index| Origin::Listed { index })
        .collect();
    for (g, spec) in sc.generators.iter().enumerate() {
        let more = crate::scenario::generators::expand(spec, &all, &format!("generators[{g}]"))?;
        origins.extend(std::iter::repeat_n(
            Origin::Generated { generator: g },
            more.len(),
        ));
        all.extend(more);
    }
    let mut feeds: Vec<(f64, usize, AppleSpec)> = Vec::new();
    for (k, src) in sc.sources.iter().enumerate() {
        feeds.extend(
            src.schedule(sc.gravity_m_s2)
                .into_iter()
                .map(|(t, a)| (t, k, a)),
        );
    }
    feeds.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    Ok(Plan {
        initial: all.into_iter().zip(origins).collect(),
        feeds,
    })
}
