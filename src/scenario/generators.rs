//! Many apples: generators that place apples at the start (a grid / layers, a seeded random
//! fill, a list read from a file) and sources that feed apples in over time. Every generated
//! apple gets a stable name, `NAME-1`, `NAME-2`, ... in generation order (a file's apples keep
//! their own names behind the prefix: `NAME-p17`), and the same seed always gives the same apples
//! (ChaCha8 from `rand_chacha`, whose output is fixed across platforms and versions).

use super::ranges::{self, num, num3};
use super::surfaces::RotationSpec;
use super::{de, AppleSpec, ScenarioError};
use crate::math::{human, vec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rapier3d_f64::math::Rotation;
use serde::de::value::{MapAccessDeserializer, SeqAccessDeserializer};
use serde::de::{Deserializer, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::Path;
use std::sync::Arc;

/// Diameter of generated apples: a fixed number, or a distribution.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum DiameterSpec {
    /// Every apple the same (m).
    Fixed(f64),
    /// A spread of sizes.
    Distribution(SizeDistribution),
}

/// A size distribution.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SizeDistribution {
    /// Mean diameter (m).
    pub mean_m: f64,
    /// Half-width of a uniform distribution, or standard deviation of a normal one (m).
    pub spread_m: f64,
    /// `uniform` (default: mean +- spread) or `normal` (clipped at +- 3 spread).
    #[serde(default)]
    pub distribution: SizeLaw,
}

/// Shape of a size distribution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SizeLaw {
    /// Uniform on [mean - spread, mean + spread].
    #[default]
    Uniform,
    /// Normal with standard deviation `spread`, clipped at 3 standard deviations.
    Normal,
}

impl<'de> Deserialize<'de> for DiameterSpec {
    // By hand rather than `untagged`, which buffers the value and loses the path of a bad field
    // inside the distribution (`diameter_m.spread_m`).
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = DiameterSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a diameter in metres or {\"mean_m\", \"spread_m\", \"distribution\"}")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<DiameterSpec, E> {
                Ok(DiameterSpec::Fixed(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<DiameterSpec, E> {
                Ok(DiameterSpec::Fixed(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<DiameterSpec, E> {
                Ok(DiameterSpec::Fixed(v as f64))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<DiameterSpec, A::Error> {
                SizeDistribution::deserialize(MapAccessDeserializer::new(map))
                    .map(DiameterSpec::Distribution)
            }
        }
        d.deserialize_any(V)
    }
}

impl DiameterSpec {
    /// Checks the numbers, naming `field`.
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        match *self {
            DiameterSpec::Fixed(d) => ranges::DIAMETER.check(field, d),
            DiameterSpec::Distribution(s) => {
                ranges::DIAMETER.check(&format!("{field}.mean_m"), s.mean_m)?;
                ranges::DIAMETER_SPREAD.check(&format!("{field}.spread_m"), s.spread_m)?;
                let (lo, hi) = (self.min_m(), self.max_m());
                if ranges::DIAMETER.contains(lo) && ranges::DIAMETER.contains(hi) {
                    return Ok(());
                }
                Err(ScenarioError::invalid(
                    format!("{field}.spread_m"),
                    format!(
                        "{} m about a mean of {} m gives diameters from {} m to {} m, outside the range of fruit handling ({}): reduce spread_m",
                        num(s.spread_m),
                        num(s.mean_m),
                        num(lo),
                        num(hi),
                        ranges::DIAMETER.describe()
                    ),
                ))
            }
        }
    }

    /// Smallest diameter the spec can give (m).
    pub fn min_m(&self) -> f64 {
        match *self {
            DiameterSpec::Fixed(d) => d,
            DiameterSpec::Distribution(s) => match s.distribution {
                SizeLaw::Uniform => s.mean_m - s.spread_m,
                SizeLaw::Normal => s.mean_m - 3.0 * s.spread_m,
            },
        }
    }

    /// Largest diameter the spec can give (m).
    pub fn max_m(&self) -> f64 {
        match *self {
            DiameterSpec::Fixed(d) => d,
            DiameterSpec::Distribution(s) => match s.distribution {
                SizeLaw::Uniform => s.mean_m + s.spread_m,
                SizeLaw::Normal => s.mean_m + 3.0 * s.spread_m,
            },
        }
    }

    /// Draws one diameter.
    pub fn sample(&self, rng: &mut ChaCha8Rng) -> f64 {
        match *self {
            DiameterSpec::Fixed(d) => d,
            DiameterSpec::Distribution(s) => draw(s.mean_m, s.spread_m, s.distribution, rng),
        }
    }
}

/// One draw of `law` about `mean` with `spread`: uniform on mean +- spread, or normal with
/// standard deviation `spread` redrawn beyond 3 of them.
fn draw(mean: f64, spread: f64, law: SizeLaw, rng: &mut ChaCha8Rng) -> f64 {
    match law {
        SizeLaw::Uniform => mean + spread * (2.0 * rng.random::<f64>() - 1.0),
        SizeLaw::Normal => {
            if spread == 0.0 {
                return mean;
            }
            // A spread that is not a finite number >= 0 is refused by validation.
            let Ok(n) = Normal::new(mean, spread) else {
                return mean;
            };
            loop {
                let x: f64 = n.sample(rng);
                if (x - mean).abs() <= 3.0 * spread {
                    return x;
                }
            }
        }
    }
}

/// Height over diameter of generated apples (`aspect`): a fixed number, or a distribution. The
/// same forms as [`DiameterSpec`], without units: `0.9`, or `{"mean": 0.9, "spread": 0.05,
/// "distribution": "normal"}`. Each apple with an aspect other than 1 is a spheroid of height
/// aspect x its diameter, turned at random (uniform over rotations); an aspect of exactly 1 is
/// a sphere, placed unturned as without `aspect`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum AspectSpec {
    /// Every apple the same height over diameter.
    Fixed(f64),
    /// A spread of aspects.
    Distribution(AspectDistribution),
}

/// A distribution of aspects (height over diameter, no unit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AspectDistribution {
    /// Mean height over diameter.
    pub mean: f64,
    /// Half-width of a uniform distribution, or standard deviation of a normal one.
    pub spread: f64,
    /// `uniform` (default: mean +- spread) or `normal` (clipped at +- 3 spread).
    #[serde(default)]
    pub distribution: SizeLaw,
}

impl<'de> Deserialize<'de> for AspectSpec {
    // By hand rather than `untagged`, which buffers the value and loses the path of a bad field
    // inside the distribution (`aspect.spread`).
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = AspectSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a height over diameter or {\"mean\", \"spread\", \"distribution\"}")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<AspectSpec, E> {
                Ok(AspectSpec::Fixed(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<AspectSpec, E> {
                Ok(AspectSpec::Fixed(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<AspectSpec, E> {
                Ok(AspectSpec::Fixed(v as f64))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<AspectSpec, A::Error> {
                AspectDistribution::deserialize(MapAccessDeserializer::new(map))
                    .map(AspectSpec::Distribution)
            }
        }
        d.deserialize_any(V)
    }
}

impl AspectSpec {
    /// Checks the numbers, naming `field` (`generators[0].aspect`).
    pub fn validate(&self, field: &str) -> Result<(), ScenarioError> {
        match *self {
            AspectSpec::Fixed(x) => ranges::ASPECT.check(field, x),
            AspectSpec::Distribution(s) => {
                ranges::ASPECT.check(&format!("{field}.mean"), s.mean)?;
                ranges::ASPECT_SPREAD.check(&format!("{field}.spread"), s.spread)?;
                let (lo, hi) = (self.min(), self.max());
                if ranges::ASPECT.contains(lo) && ranges::ASPECT.contains(hi) {
                    return Ok(());
                }
                Err(ScenarioError::invalid(
                    format!("{field}.spread"),
                    format!(
                        "{} about a mean of {} gives aspects from {} to {}, outside the range of fruit handling ({}): reduce spread",
                        num(s.spread),
                        num(s.mean),
                        num3(lo),
                        num3(hi),
                        ranges::ASPECT.describe()
                    ),
                ))
            }
        }
    }

    /// Smallest aspect the spec can give.
    pub fn min(&self) -> f64 {
        match *self {
            AspectSpec::Fixed(x) => x,
            AspectSpec::Distribution(s) => match s.distribution {
                SizeLaw::Uniform => s.mean - s.spread,
                SizeLaw::Normal => s.mean - 3.0 * s.spread,
            },
        }
    }

    /// Largest aspect the spec can give.
    pub fn max(&self) -> f64 {
        match *self {
            AspectSpec::Fixed(x) => x,
            AspectSpec::Distribution(s) => match s.distribution {
                SizeLaw::Uniform => s.mean + s.spread,
                SizeLaw::Normal => s.mean + 3.0 * s.spread,
            },
        }
    }

    /// Whether every apple is a sphere (an aspect of exactly 1): then nothing is drawn.
    pub fn is_sphere(&self) -> bool {
        *self == AspectSpec::Fixed(1.0)
    }

    /// Draws one aspect.
    pub fn sample(&self, rng: &mut ChaCha8Rng) -> f64 {
        match *self {
            AspectSpec::Fixed(x) => x,
            AspectSpec::Distribution(s) => draw(s.mean, s.spread, s.distribution, rng),
        }
    }

    /// The largest bounding diameter of an apple of diameter at most `largest_diameter_m` with
    /// this aspect, whatever its orientation (m).
    pub fn bounding_diameter_m(aspect: Option<&AspectSpec>, largest_diameter_m: f64) -> f64 {
        match aspect {
            Some(a) if !a.is_sphere() => largest_diameter_m * a.max().max(1.0),
            _ => largest_diameter_m,
        }
    }
}

/// The ChaCha8 stream of a generator's or source's seed that its shapes are drawn from. Its
/// sizes, positions and jitter keep stream 0, as before shapes existed: a scenario without
/// `aspect` gives the apples it always gave, and adding one changes their shapes only.
pub const SHAPE_STREAM: u64 = 1;

/// The shapes of a generator's or source's apples: an aspect and a uniform random orientation
/// per apple, from the [`SHAPE_STREAM`] of its seed.
struct Shapes {
    aspect: AspectSpec,
    rng: ChaCha8Rng,
}

impl Shapes {
    /// `None` without an aspect, or with an aspect of exactly 1 (spheres, drawn as before).
    fn new(aspect: Option<&AspectSpec>, seed: u64) -> Option<Self> {
        let aspect = *aspect.filter(|a| !a.is_sphere())?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(SHAPE_STREAM);
        Some(Self { aspect, rng })
    }

    /// The height and orientation of the next apple, of diameter `d`: its aspect first, then
    /// three draws for its orientation.
    fn draw(&mut self, d: f64) -> (f64, RotationSpec) {
        let h = d * self.aspect.sample(&mut self.rng);
        let u = [0; 3].map(|_| self.rng.random::<f64>());
        (h, uniform_rotation(u))
    }
}

/// The orientation of three uniform draws in [0, 1), uniform over rotations (Shoemake's unit
/// quaternion, *Graphics Gems III*, "Uniform random rotations"), written as an axis and an
/// angle in [0, 180] degrees (the quaternion with w >= 0).
pub fn uniform_rotation(u: [f64; 3]) -> RotationSpec {
    use std::f64::consts::TAU;
    let (s1, s2) = ((1.0 - u[0]).sqrt(), u[0].sqrt());
    let (t1, t2) = (TAU * u[1], TAU * u[2]);
    let q = Rotation::from_xyzw(s1 * t1.sin(), s1 * t1.cos(), s2 * t2.sin(), s2 * t2.cos());
    let q = if q.w < 0.0 { -q } else { q };
    let (axis, angle) = q.to_axis_angle();
    RotationSpec {
        axis: Some(axis.to_array()),
        angle_deg: Some(angle.to_degrees()),
        euler_xyz_deg: None,
    }
}

/// An apple generator. `type` selects the kind. (Read by hand, through the scenario's `de`
/// module, so that a mistake inside a generator names its exact field.)
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum GeneratorSpec {
    /// Apples on a regular grid: `count` = [nx, ny, nz] (nz layers), centres `spacing_m` apart,
    /// the first at `origin_m`; layer by layer from the bottom, x fastest.
    Grid(GridSpec),
    /// `count` apples at random, non-overlapping positions inside a box region.
    RandomFill(RandomFillSpec),
    /// Apples listed in a JSON file (name, diameter, position each), e.g. a pile written by
    /// another program that applesim is compared with.
    File(FileSpec),
}

impl<'de> Deserialize<'de> for GeneratorSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const TYPES: &[&str] = &["grid", "random_fill", "file"];
        let (t, v) = de::tagged(d, TYPES)?;
        Ok(match t {
            "grid" => GeneratorSpec::Grid(de::from_value(v)?),
            "random_fill" => GeneratorSpec::RandomFill(de::from_value(v)?),
            _ => GeneratorSpec::File(de::from_value(v)?),
        })
    }
}

impl GeneratorSpec {
    /// How many apples the generator places (counted, not generated: what must be checked
    /// before generating).
    pub fn count(&self) -> f64 {
        match self {
            GeneratorSpec::Grid(s) => s.count.iter().map(|&c| f64::from(c)).product(),
            GeneratorSpec::RandomFill(s) => f64::from(s.count),
            GeneratorSpec::File(s) => s.loaded.as_ref().map_or(0, |l| l.0.len()) as f64,
        }
    }

    /// Name prefix of the generated apples.
    pub fn name(&self) -> &str {
        match self {
            GeneratorSpec::Grid(g) => &g.name,
            GeneratorSpec::RandomFill(g) => &g.name,
            GeneratorSpec::File(g) => &g.name,
        }
    }
}

/// A grid of apples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// Name prefix.
    pub name: String,
    /// Material name.
    pub material: String,
    /// Diameters.
    pub diameter_m: DiameterSpec,
    /// Height over diameter ([`AspectSpec`]): spheroids turned at random. Absent: spheres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aspect: Option<AspectSpec>,
    /// Mass of every apple (kg); default from density.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Number of apples along x, y and z.
    pub count: [u32; 3],
    /// Centre-to-centre spacing along x, y, z (m).
    pub spacing_m: [f64; 3],
    /// Centre of the first apple (m).
    pub origin_m: [f64; 3],
    /// Random sideways (x, y) offset of each apple, uniform in +- this (m).
    #[serde(default)]
    pub jitter_m: f64,
    /// Seed of sizes and jitter.
    #[serde(default)]
    pub seed: u64,
    /// Initial velocity of every apple (m/s).
    #[serde(default)]
    pub velocity_m_s: [f64; 3],
}

/// A random fill.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomFillSpec {
    /// Name prefix.
    pub name: String,
    /// Material name.
    pub material: String,
    /// Diameters.
    pub diameter_m: DiameterSpec,
    /// Height over diameter ([`AspectSpec`]): spheroids turned at random. Absent: spheres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aspect: Option<AspectSpec>,
    /// Mass of every apple (kg); default from density.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Number of apples.
    pub count: u32,
    /// Corner of the region holding the apples (whole apples, not just centres) (m).
    pub region_min_m: [f64; 3],
    /// Opposite corner (m).
    pub region_max_m: [f64; 3],
    /// Seed.
    pub seed: u64,
    /// Initial velocity of every apple (m/s).
    #[serde(default)]
    pub velocity_m_s: [f64; 3],
}

/// Apples read from a JSON file: an array of `{"name", "diameter_m", "position_m"}` objects (the
/// `pile.json` of the LIGGGHTS reference run, for instance), each with an optional `height_m`
/// and `rotation` (a spheroid, as in `apples[]`). The file is read once, when the
/// scenario is loaded ([`super::Scenario::read_files`]), because the scenario's folder is known
/// only then; the apples are kept in [`FileSpec::loaded`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileSpec {
    /// Name prefix: apple `p17` of the file becomes `NAME-p17`.
    pub name: String,
    /// Material name.
    pub material: String,
    /// The JSON file, relative to the scenario's folder (or absolute).
    pub file: String,
    /// Mass of every apple (kg); default from density.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Initial velocity of every apple (m/s).
    #[serde(default)]
    pub velocity_m_s: [f64; 3],
    /// The apples read from `file` (not part of the JSON: the scenario as written keeps the file
    /// name, not its contents). `None` until the file is read.
    #[serde(skip)]
    pub loaded: Option<FileApples>,
}

/// One apple of a file generator's list, exactly as in the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileApple {
    /// Name in the file (unique within it).
    pub name: String,
    /// Diameter (m): the equatorial one of a spheroid.
    pub diameter_m: f64,
    /// Height along its own z axis (m); absent: a sphere (as [`AppleSpec::height_m`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_m: Option<f64>,
    /// Starting orientation (as [`AppleSpec::rotation`]); absent: unturned.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<RotationSpec>,
    /// Centre (m).
    pub position_m: [f64; 3],
}

/// The apples of a file, shared between clones of the scenario (a pile file holds thousands).
#[derive(Clone, PartialEq)]
pub struct FileApples(pub Arc<Vec<FileApple>>);

impl std::fmt::Debug for FileApples {
    // Thousands of apples would drown any debug print of the scenario.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FileApples({} apples)", self.0.len())
    }
}

impl FileSpec {
    /// Reads and parses `file`, resolved against `base_dir` (the scenario's folder); `field` is
    /// the generator's JSON path (`generators[0]`), named in errors as `generators[0].file`.
    /// Only the format is checked here; the values are checked by [`super::validate`].
    pub fn read(&mut self, base_dir: &Path, field: &str) -> Result<(), ScenarioError> {
        let f = format!("{field}.file");
        if self.file.trim().is_empty() {
            return Err(ScenarioError::invalid(f, "empty file name"));
        }
        let path = base_dir.join(&self.file);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            ScenarioError::invalid(&f, format!("cannot read '{}': {e}", path.display()))
        })?;
        let shown = path.display().to_string();
        let apples: Vec<FileApple> = super::parse_one(&text, &shown).map_err(|e| {
            let (at, message) = match e {
                ScenarioError::Parse { path, message, .. } => (path, message),
                other => (".".to_string(), other.to_string()),
            };
            ScenarioError::invalid(
                &f,
                format!(
                    "'{shown}'{}: {message} (expected an array of {{\"name\", \"diameter_m\", \"position_m\"}}, each with an optional \"height_m\" and \"rotation\")",
                    if at.is_empty() || at == "." {
                        String::new()
                    } else {
                        format!(" at {at}")
                    },
                ),
            )
        })?;
        self.loaded = Some(FileApples(Arc::new(apples)));
        Ok(())
    }
}

/// A source that feeds apples in over time, for lines.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceSpec {
    /// Name prefix of the emitted apples.
    pub name: String,
    /// Material name.
    pub material: String,
    /// Diameters.
    pub diameter_m: DiameterSpec,
    /// Height over diameter ([`AspectSpec`]): spheroids turned at random. Absent: spheres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aspect: Option<AspectSpec>,
    /// Mass of every apple (kg); default from density.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Where apples appear (m); may be left out for a source placed `on` a surface.
    #[serde(default = "super::layout::unset")]
    pub position_m: [f64; 3],
    /// Placed on a surface, the spawn point resting on it (resolved into `position_m` when
    /// loaded; the largest apple of the size distribution just clears it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on: Option<super::layout::OnSpec>,
    /// Random offset of the appearing point (m): a number scatters it across gravity only
    /// (uniform in +- this along each horizontal axis), `[jx, jy, jz]` along each axis of the
    /// source's frame ([`JitterSpec`]).
    #[serde(default)]
    pub jitter_m: JitterSpec,
    /// Velocity of the emitted apples (m/s), relative to the source (turned with it when it
    /// turns).
    #[serde(default)]
    pub velocity_m_s: [f64; 3],
    /// The source's prescribed motion, the same as a surface's (`scenario::motion`): a fill head
    /// lowered with a bin, a filler arm that swings. Apples appear where it carries the source at
    /// their spawn time, with its velocity there added to their own. Fixed when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<super::motion::MotionSpec>,
    /// Apples per second.
    pub rate_per_s: f64,
    /// First emission (s).
    #[serde(default)]
    pub start_s: f64,
    /// Number of apples to emit.
    pub count: u32,
    /// Seed of sizes and jitter.
    #[serde(default)]
    pub seed: u64,
}

impl SourceSpec {
    /// The scheduled emissions: (time, apple), in order, each apple placed where the source is
    /// when it is at rest (`position_m` plus its jitter offset; a moving source carries it from
    /// there at the spawn time, `world::motion::Motion::spawn`). `gravity_m_s2` says what a
    /// number `jitter_m` leaves out ([`JitterSpec::offset`]). An emission whose spot is still
    /// taken is postponed by the driver until it is free.
    pub fn schedule(&self, gravity_m_s2: [f64; 3]) -> Vec<(f64, AppleSpec)> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        let mut shapes = Shapes::new(self.aspect.as_ref(), self.seed);
        let g = vec3(gravity_m_s2);
        (0..self.count)
            .map(|k| {
                let d = self.diameter_m.sample(&mut rng);
                let mut p = vec3(self.position_m);
                if !self.jitter_m.is_zero() {
                    // Three draws whatever the form, so that a number keeps the horizontal
                    // offsets it always gave (the same stream of draws).
                    let u = [0; 3].map(|_| 2.0 * rng.random::<f64>() - 1.0);
                    p += self.jitter_m.offset(u, g);
                }
                let (height_m, rotation) = shapes.as_mut().map(|s| s.draw(d)).unzip();
                (
                    self.start_s + k as f64 / self.rate_per_s,
                    AppleSpec {
                        name: format!("{}-{}", self.name, k + 1),
                        material: self.material.clone(),
                        diameter_m: d,
                        height_m,
                        rotation,
                        mass_kg: self.mass_kg,
                        position_m: [p.x, p.y, p.z],
                        velocity_m_s: self.velocity_m_s,
                        angular_velocity_rad_s: [0.0; 3],
                        probe: None,
                        on: None,
                    },
                )
            })
            .collect()
    }

    /// Whether the feed is exactly symmetric under `gravity_m_s2`: at least
    /// [`SYMMETRIC_FEED_APPLES`] apples from one spot with no jitter across gravity, the spot
    /// not carried across gravity (no rotation, a translation along gravity only). Every apple
    /// then starts on one vertical line with the same velocity, so they all move, collide and
    /// pile in one vertical plane (on one vertical line when the velocity is vertical), which
    /// no real feed does. Without gravity nothing piles: never.
    pub fn is_symmetric(&self, gravity_m_s2: [f64; 3]) -> bool {
        let g = vec3(gravity_m_s2);
        let gl = g.length();
        if self.count < SYMMETRIC_FEED_APPLES || !(gl > 0.0 && gl.is_finite()) {
            return false;
        }
        let down = g / gl;
        // Whether a vector lies along gravity (no component across it).
        let along = |v: Vec3| v.cross(down).length() <= 1e-12 * v.length();
        let jitter_along = match self.jitter_m {
            JitterSpec::Horizontal(j) => j == 0.0,
            JitterSpec::PerAxis(j) => (0..3).all(|c| j[c] == 0.0 || along(Vec3::AXES[c])),
        };
        let still = match &self.motion {
            None => true,
            Some(m) if m.rotation.is_some() => false,
            Some(m) => m.translation.as_ref().is_none_or(|t| {
                t.velocity_m_s.is_none_or(|v| along(vec3(v)))
                    && t.keyframes
                        .as_ref()
                        .is_none_or(|k| k.iter().all(|(_, x)| along(vec3(*x) - vec3(k[0].1))))
            }),
        };
        jitter_along && still
    }
}

/// The fewest apples from one spot that make an exactly symmetric feed worth a warning
/// ([`SourceSpec::is_symmetric`]): two to four apples fed onto a belt, one after the other, are
/// a test of the belt, not a pile.
pub const SYMMETRIC_FEED_APPLES: u32 = 5;

/// The warnings of a scenario's exactly symmetric feeds ([`SourceSpec::is_symmetric`]), one
/// per source, in scenario order: the run adds them to its warnings (`summary.json`
/// `warnings`, and the terminal at the end of the run).
pub fn symmetric_feed_warnings(sources: &[SourceSpec], gravity_m_s2: [f64; 3]) -> Vec<String> {
    sources
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_symmetric(gravity_m_s2))
        .map(|(k, s)| {
            let p = s.position_m;
            format!(
                "source '{}' (sources[{k}]) feeds {} apples from one spot with no jitter across gravity: every apple starts on the vertical line through [{}, {}, {}] m with the same velocity, so they all move, collide and pile in one vertical plane, an exactly symmetric feed that no real line has (a pile of them stands in that plane, higher than real fruit would); give sources[{k}].jitter_m a sideways scatter (e.g. 0.01 m) to break the symmetry",
                s.name,
                s.count,
                human(p[0], 6, 3),
                human(p[1], 6, 3),
                human(p[2], 6, 3),
            )
        })
        .collect()
}

/// How far a source scatters the spot where its apples appear (`jitter_m`, m): each apple's
/// offset is drawn uniform in +- the half-widths, once, when the feed is planned.
///
/// - A number `j` scatters across gravity only: along each horizontal axis (x and y when gravity
///   is along -z), never up or down, so that apples fall from the height the scenario gives.
///   The offset is drawn in +- j on each axis, then its component along gravity is taken out
///   (without gravity nothing is vertical: every axis).
/// - `[jx, jy, jz]` scatters along each axis of the source's frame (the world's axes, turned
///   with the source when its `motion` turns it): `[0.03, 0.03, 0.03]` is the scatter a number
///   gave before issue 31, vertical included.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum JitterSpec {
    /// Across gravity only, +- this on each horizontal axis (m).
    Horizontal(f64),
    /// +- jx, jy, jz along x, y and z (m).
    PerAxis([f64; 3]),
}

impl Default for JitterSpec {
    fn default() -> Self {
        JitterSpec::Horizontal(0.0)
    }
}

impl From<f64> for JitterSpec {
    fn from(j: f64) -> Self {
        JitterSpec::Horizontal(j)
    }
}

impl<'de> Deserialize<'de> for JitterSpec {
    // By hand rather than `untagged`, which buffers the value and loses the path of a bad
    // component (`jitter_m[2]`).
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = JitterSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a jitter in metres (across gravity) or [jx, jy, jz]")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<JitterSpec, E> {
                Ok(JitterSpec::Horizontal(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<JitterSpec, E> {
                Ok(JitterSpec::Horizontal(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<JitterSpec, E> {
                Ok(JitterSpec::Horizontal(v as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<JitterSpec, A::Error> {
                <[f64; 3]>::deserialize(SeqAccessDeserializer::new(seq)).map(JitterSpec::PerAxis)
            }
        }
        d.deserialize_any(V)
    }
}

impl JitterSpec {
    /// Whether every offset is zero.
    pub fn is_zero(&self) -> bool {
        match *self {
            JitterSpec::Horizontal(j) => j == 0.0,
            JitterSpec::PerAxis(j) => j.iter().all(|&x| x == 0.0),
        }
    }

    /// The largest offset along each world axis, at most (m): a box the scatter stays in,
    /// whatever gravity takes out of a number's.
    pub fn bound_m(&self) -> [f64; 3] {
        match *self {
            JitterSpec::Horizontal(j) => [j.abs(); 3],
            JitterSpec::PerAxis(j) => j.map(f64::abs),
        }
    }

    /// The values given, for range checks: (JSON path suffix, value) of each.
    pub fn values(&self) -> Vec<(String, f64)> {
        match *self {
            JitterSpec::Horizontal(j) => vec![(String::new(), j)],
            JitterSpec::PerAxis(j) => (0..3).map(|c| (format!("[{c}]"), j[c])).collect(),
        }
    }

    /// The offset of draws `u` (each in [-1, 1]) under gravity `g` (m/s^2), in the source's
    /// frame at rest: `j u` with its component along gravity taken out for a number (every axis
    /// without gravity), `(jx u0, jy u1, jz u2)` for a vector.
    pub fn offset(&self, u: [f64; 3], g: Vec3) -> Vec3 {
        match *self {
            JitterSpec::Horizontal(j) => {
                let o = j * Vec3::from_array(u);
                let gl = g.length();
                if gl > 0.0 && gl.is_finite() {
                    let down = g / gl;
                    o - down * o.dot(down)
                } else {
                    o
                }
            }
            JitterSpec::PerAxis(j) => Vec3::new(j[0] * u[0], j[1] * u[1], j[2] * u[2]),
        }
    }

    /// The largest offset along each axis (m), in the source's frame at rest: the half-widths of
    /// the box every spawn point lies in.
    pub fn half_widths(&self, g: Vec3) -> [f64; 3] {
        match *self {
            JitterSpec::PerAxis(j) => j,
            JitterSpec::Horizontal(j) => {
                // Row c of the projector across gravity, summed in absolute value: the largest
                // |offset_c| over the cube of draws.
                let gl = g.length();
                if !(gl > 0.0 && gl.is_finite()) {
                    return [j; 3];
                }
                let d = g / gl;
                [0, 1, 2].map(|c| {
                    (0..3)
                        .map(|i| (f64::from(u8::from(c == i)) - d[c] * d[i]).abs())
                        .sum::<f64>()
                        * j
                })
            }
        }
    }
}

/// Apples placed so far, hashed on cells at least as wide as the largest diameter, so that a
/// random fill checks a candidate against its neighbours only (the same test as against every
/// apple: two apples in cells that are not neighbours are more than a cell apart).
struct FreeSpace {
    cell_m: f64,
    cells: std::collections::HashMap<[i64; 3], Vec<(Vec3, f64)>>,
}

impl FreeSpace {
    fn new(largest_diameter_m: f64) -> Self {
        let ok = largest_diameter_m.is_finite() && largest_diameter_m > 0.0;
        Self {
            cell_m: if ok { largest_diameter_m } else { 1.0 },
            cells: Default::default(),
        }
    }

    fn cell(&self, p: Vec3) -> [i64; 3] {
        // `as` saturates: far-away apples share the outermost cells, which stays correct.
        [p.x, p.y, p.z].map(|x| (x / self.cell_m).floor() as i64)
    }

    fn insert(&mut self, p: Vec3, r: f64) {
        let c = self.cell(p);
        self.cells.entry(c).or_default().push((p, r));
    }

    /// Whether a sphere of radius `r` at `p` overlaps none of the apples placed.
    fn is_free(&self, p: Vec3, r: f64) -> bool {
        let [x, y, z] = self.cell(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let key = [
                        x.saturating_add(dx),
                        y.saturating_add(dy),
                        z.saturating_add(dz),
                    ];
                    if let Some(list) = self.cells.get(&key) {
                        if list.iter().any(|&(q, rq)| (q - p).length() < r + rq) {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }
}

/// The apples of one generator, given the apples already placed (a random fill avoids them).
pub fn expand(
    g: &GeneratorSpec,
    placed: &[AppleSpec],
    field: &str,
) -> Result<Vec<AppleSpec>, ScenarioError> {
    match g {
        GeneratorSpec::Grid(s) => {
            let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
            let mut shapes = Shapes::new(s.aspect.as_ref(), s.seed);
            let mut out = Vec::new();
            let o = vec3(s.origin_m);
            let sp = vec3(s.spacing_m);
            for k in 0..s.count[2] {
                for j in 0..s.count[1] {
                    for i in 0..s.count[0] {
                        let d = s.diameter_m.sample(&mut rng);
                        let mut p =
                            o + Vec3::new(i as f64 * sp.x, j as f64 * sp.y, k as f64 * sp.z);
                        if s.jitter_m > 0.0 {
                            p.x += s.jitter_m * (2.0 * rng.random::<f64>() - 1.0);
                            p.y += s.jitter_m * (2.0 * rng.random::<f64>() - 1.0);
                        }
                        let (height_m, rotation) = shapes.as_mut().map(|s| s.draw(d)).unzip();
                        out.push(AppleSpec {
                            name: format!("{}-{}", s.name, out.len() + 1),
                            material: s.material.clone(),
                            diameter_m: d,
                            height_m,
                            rotation,
                            mass_kg: s.mass_kg,
                            position_m: [p.x, p.y, p.z],
                            velocity_m_s: s.velocity_m_s,
                            angular_velocity_rad_s: [0.0; 3],
                            probe: None,
                            on: None,
                        });
                    }
                }
            }
            Ok(out)
        }
        GeneratorSpec::RandomFill(s) => {
            let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
            let mut shapes = Shapes::new(s.aspect.as_ref(), s.seed);
            let lo = vec3(s.region_min_m);
            let hi = vec3(s.region_max_m);
            let mut out: Vec<AppleSpec> = Vec::new();
            // Random sequential placement jams near 38 % of the volume; beyond the 64 % of a
            // random close packing no attempt can succeed: refuse at once, not after
            // 1000 attempts per apple.
            let volume = (hi - lo).max(Vec3::ZERO).element_product();
            // Apples are placed by their bounding balls (a spheroid's turned at random): the
            // smallest of those.
            let smallest = match shapes {
                Some(ref sh) => s.diameter_m.min_m() * sh.aspect.min().max(1.0),
                None => s.diameter_m.min_m(),
            };
            if (hi - lo - Vec3::splat(smallest)).min_element() < 0.0 {
                // The region, not the count: no apple fits in it at all.
                return Err(ScenarioError::invalid(
                    format!("{field}.region_max_m"),
                    format!("the region is smaller than an apple of {smallest} m"),
                ));
            }
            let needed = s.count as f64 * std::f64::consts::PI / 6.0 * smallest.powi(3);
            if needed > 0.64 * volume {
                return Err(ScenarioError::invalid(
                    format!("{field}.count"),
                    format!(
                        "{} apples of at least {} m fill {} m^3, more than the {} m^3 a random packing of the region holds: enlarge the region or lower the count",
                        s.count,
                        num(smallest),
                        num3(needed),
                        num3(0.64 * volume)
                    ),
                ));
            }
            let mut attempts = 0u64;
            let max_attempts = 1000 * s.count as u64 + 10_000;
            let mut space =
                FreeSpace::new(placed.iter().map(|a| 2.0 * a.bounding_radius_m()).fold(
                    AspectSpec::bounding_diameter_m(s.aspect.as_ref(), s.diameter_m.max_m()),
                    f64::max,
                ));
            for a in placed {
                space.insert(vec3(a.position_m), a.bounding_radius_m());
            }
            while out.len() < s.count as usize {
                let d = s.diameter_m.sample(&mut rng);
                // A spheroid's shape from its own stream, before its place (which its bounding
                // ball decides); a sphere's draws are those it always had.
                let (height_m, rotation) = shapes.as_mut().map(|sh| sh.draw(d)).unzip();
                let span_d = height_m.map_or(d, |h: f64| d.max(h));
                let r = span_d / 2.0;
                let span = hi - lo - Vec3::splat(span_d);
                if span.min_element() < 0.0 {
                    return Err(ScenarioError::invalid(
                        format!("{field}.region_max_m"),
                        format!("the region is smaller than an apple of {span_d} m"),
                    ));
                }
                let p = lo
                    + Vec3::splat(r)
                    + Vec3::new(
                        span.x * rng.random::<f64>(),
                        span.y * rng.random::<f64>(),
                        span.z * rng.random::<f64>(),
                    );
                attempts += 1;
                let free = space.is_free(p, r);
                if free {
                    space.insert(p, r);
                    out.push(AppleSpec {
                        name: format!("{}-{}", s.name, out.len() + 1),
                        material: s.material.clone(),
                        diameter_m: d,
                        height_m,
                        rotation,
                        mass_kg: s.mass_kg,
                        position_m: [p.x, p.y, p.z],
                        velocity_m_s: s.velocity_m_s,
                        angular_velocity_rad_s: [0.0; 3],
                        probe: None,
                        on: None,
                    });
                } else if attempts > max_attempts {
                    return Err(ScenarioError::invalid(
                        format!("{field}.count"),
                        format!(
                            "placed only {} of {} apples without overlap after {attempts} attempts: enlarge the region or lower the count",
                            out.len(),
                            s.count
                        ),
                    ));
                }
            }
            Ok(out)
        }
        GeneratorSpec::File(s) => {
            let Some(list) = &s.loaded else {
                return Err(ScenarioError::invalid(
                    format!("{field}.file"),
                    format!(
                        "'{}' has not been read: load the scenario with scenario::load, or call Scenario::read_files with its folder",
                        s.file
                    ),
                ));
            };
            Ok(list
                .0
                .iter()
                .map(|a| AppleSpec {
                    name: format!("{}-{}", s.name, a.name),
                    material: s.material.clone(),
                    diameter_m: a.diameter_m,
                    height_m: a.height_m,
                    rotation: a.rotation.clone(),
                    mass_kg: s.mass_kg,
                    position_m: a.position_m,
                    velocity_m_s: s.velocity_m_s,
                    angular_velocity_rad_s: [0.0; 3],
                    probe: None,
                    on: None,
                })
                .collect())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_rotation_reads_back_as_drawn() {
        // u = (0, 0, x): the quaternion (0, 1, 0, 0), half a turn about y.
        let r = uniform_rotation([0.0, 0.0, 0.3]);
        assert_eq!(r.axis, Some([0.0, 1.0, 0.0]));
        assert_eq!(r.angle_deg, Some(180.0));
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..1000 {
            let u = [0; 3].map(|_| rng.random::<f64>());
            let (s1, s2) = ((1.0 - u[0]).sqrt(), u[0].sqrt());
            let (t1, t2) = (std::f64::consts::TAU * u[1], std::f64::consts::TAU * u[2]);
            let q = Rotation::from_xyzw(s1 * t1.sin(), s1 * t1.cos(), s2 * t2.sin(), s2 * t2.cos());
            let spec = uniform_rotation(u);
            let angle = spec.angle_deg.unwrap();
            assert!((0.0..=180.0).contains(&angle), "{angle}");
            let back = spec.to_rotation("r").unwrap();
            let d = (back - q).length().min((back + q).length());
            assert!(d < 1e-14, "{u:?}: {d:e}");
        }
    }

    #[test]
    fn aspect_reads_as_a_number_or_a_distribution() {
        let f: AspectSpec = serde_json::from_str("0.9").unwrap();
        assert_eq!(f, AspectSpec::Fixed(0.9));
        let d: AspectSpec =
            serde_json::from_str(r#"{"mean": 0.9, "spread": 0.05, "distribution": "normal"}"#)
                .unwrap();
        assert_eq!((d.min(), d.max()), (0.9 - 0.15, 0.9 + 0.15));
        assert!(serde_json::from_str::<AspectSpec>(r#"{"mean_m": 0.9, "spread": 0.05}"#).is_err());
        assert!(AspectSpec::Fixed(1.0).is_sphere() && !d.is_sphere());
        // Up to 1.05: the tallest apple is 84 mm high; an oblate one is bounded by its diameter.
        assert_eq!(AspectSpec::bounding_diameter_m(Some(&d), 0.08), 0.08 * 1.05);
        let flat = AspectSpec::Fixed(0.8);
        assert_eq!(AspectSpec::bounding_diameter_m(Some(&flat), 0.08), 0.08);
        let tall = AspectSpec::Fixed(1.25);
        assert_eq!(AspectSpec::bounding_diameter_m(Some(&tall), 0.08), 0.1);
        assert_eq!(AspectSpec::bounding_diameter_m(None, 0.08), 0.08);
    }
}
