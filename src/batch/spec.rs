//! Batch specs and their expansion into runs.
//!
//! A spec is a JSON file (format in docs/batch.md):
//!
//! ```json
//! {
//!   "description": "impact speed x apple size on steel",
//!   "base": "../drop_on_steel.json",
//!   "set": { "/duration_s": 0.05 },
//!   "parameters": [
//!     { "name": "vz_m_s", "path": "/apples/0/velocity_m_s/2",
//!       "range": { "start": -0.2, "stop": -1.4, "step": -0.2 } },
//!     { "name": "diameter_m", "path": "/apples/0/diameter_m", "values": [0.06, 0.08, 0.1],
//!       "group": "size" },
//!     { "name": "z0_m", "path": "/apples/0/position_m/2", "values": [0.0301, 0.0401, 0.0501],
//!       "group": "size" }
//!   ]
//! }
//! ```
//!
//! `base` is a scenario file (relative to the spec) or an inline scenario; `set` changes fields
//! of every run; each parameter sets the field its JSON Pointer `path` names to each of its
//! `values` (or the values of its `range`). Parameters form a full grid, the first one varying
//! slowest; parameters with the same `group` move together (zipped) as one axis of the grid, and
//! `"mode": "zip"` zips all of them. Or the spec is a folder: every `*.json` file in it (not in
//! sub-folders), sorted by name, is one run.
//!
//! Expansion only substitutes values: each run is then parsed and validated like any scenario
//! file when it runs, so a run the substitution made invalid fails alone, with the scenario's own
//! message, and the rest of the batch goes on.

use super::id;
use super::pointer;
use super::BatchError;
use serde::Deserialize;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Most runs one spec may expand to: a guard against a typo that multiplies a grid by 1000.
pub const MAX_RUNS: usize = 1_000_000;

/// Column names of `merged.csv` that a parameter may not take.
pub const RESERVED_NAMES: [&str; 4] = ["index", "id", "status", "error"];

/// How the parameter axes combine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Every combination (groups of zipped parameters count as one axis).
    #[default]
    Grid,
    /// All parameters zipped: run k takes the k-th value of each (equal lengths).
    Zip,
}

/// A range of numbers, `stop` included.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSpec {
    /// First value.
    pub start: f64,
    /// Last value (included when the steps land on it, to 1e-9 of a step).
    pub stop: f64,
    /// Step between values (its sign must lead from start to stop).
    #[serde(default)]
    pub step: Option<f64>,
    /// Number of values, evenly spaced from start to stop (give `step` or `count`).
    #[serde(default)]
    pub count: Option<usize>,
}

/// One varied parameter as written in the spec.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamSpec {
    /// Column name in `merged.csv` and key in `params.json` (default: the path).
    #[serde(default)]
    pub name: Option<String>,
    /// JSON Pointer of the scenario field it sets.
    pub path: String,
    /// The values, any JSON (numbers, vectors, strings, whole objects).
    #[serde(default)]
    pub values: Option<Vec<Value>>,
    /// Or a range of numbers.
    #[serde(default)]
    pub range: Option<RangeSpec>,
    /// Parameters with the same group are zipped into one axis of the grid.
    #[serde(default)]
    pub group: Option<String>,
}

/// A batch spec file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpecFile {
    /// Free text, copied to `batch.json`.
    #[serde(default)]
    pub description: Option<String>,
    /// A scenario file path (relative to the spec) or an inline scenario object.
    pub base: Value,
    /// Grid (default) or zip.
    #[serde(default)]
    pub mode: Mode,
    /// Fields set in every run (JSON Pointer -> value), before the parameters.
    #[serde(default)]
    pub set: BTreeMap<String, Value>,
    /// The varied parameters.
    #[serde(default)]
    pub parameters: Vec<ParamSpec>,
}

/// A varied parameter: one column of `merged.csv`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, Deserialize)]
pub struct Parameter {
    /// Column name.
    pub name: String,
    /// JSON Pointer it sets (empty for the `file` column of a folder batch).
    pub path: String,
}

/// One run of the expansion.
#[derive(Debug, Clone)]
pub struct PlannedRun {
    /// Position in expansion order (0-based).
    pub index: usize,
    /// Stable id ([`id::run_id`] of the expanded scenario).
    pub id: String,
    /// The value of each parameter, in the order of [`Batch::parameters`].
    pub values: Vec<Value>,
    /// The expanded scenario, or why there is none (a folder file that is not JSON).
    pub scenario: Result<Value, String>,
    /// How messages name the run's scenario (`spec.json run 3`, or the file).
    pub label: String,
}

impl PlannedRun {
    /// The parameter values by name.
    pub fn params(&self, parameters: &[Parameter]) -> BTreeMap<String, Value> {
        parameters
            .iter()
            .zip(&self.values)
            .map(|(p, v)| (p.name.clone(), v.clone()))
            .collect()
    }
}

/// An expanded batch.
#[derive(Debug, Clone)]
pub struct Batch {
    /// The spec's description.
    pub description: Option<String>,
    /// Where relative paths of the runs' scenarios resolve: the base scenario file's folder
    /// (as for `applesim run` of that file), the spec's folder for an inline base, the folder
    /// itself for a folder batch.
    pub base_dir: PathBuf,
    /// The varied parameters (columns).
    pub parameters: Vec<Parameter>,
    /// The runs in expansion order.
    pub runs: Vec<PlannedRun>,
}

fn spec_err(file: &Path, field: impl Into<String>, message: impl Into<String>) -> BatchError {
    BatchError::Spec {
        file: file.display().to_string(),
        field: field.into(),
        message: message.into(),
    }
}

/// Loads a spec file, or a folder of scenario files, and expands it.
pub fn load(path: &Path) -> Result<Batch, BatchError> {
    if path.is_dir() {
        return load_folder(path);
    }
    let text = std::fs::read_to_string(path).map_err(|source| BatchError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    expand_text(&text, path, &dir)
}

/// Parses and expands spec text; `file` names it in messages and `dir` is where a relative
/// `base` path resolves.
pub fn expand_text(text: &str, file: &Path, dir: &Path) -> Result<Batch, BatchError> {
    let de = &mut serde_json::Deserializer::from_str(text);
    let spec: SpecFile = serde_path_to_error::deserialize(de).map_err(|e| {
        let p = e.path().to_string();
        spec_err(
            file,
            if p.is_empty() { ".".into() } else { p },
            e.into_inner().to_string(),
        )
    })?;
    expand(&spec, file, dir)
}

/// Expands a parsed spec.
pub fn expand(spec: &SpecFile, file: &Path, dir: &Path) -> Result<Batch, BatchError> {
    let (mut base, base_dir) = match &spec.base {
        Value::String(rel) => {
            let p = dir.join(rel);
            let text = std::fs::read_to_string(&p).map_err(|e| {
                spec_err(file, "base", format!("cannot read '{}': {e}", p.display()))
            })?;
            let v: Value = serde_json::from_str(&text).map_err(|e| {
                spec_err(
                    file,
                    "base",
                    format!("'{}' is not valid JSON: {e}", p.display()),
                )
            })?;
            (v, p.parent().map(Path::to_path_buf).unwrap_or_default())
        }
        Value::Object(_) => (spec.base.clone(), dir.to_path_buf()),
        _ => {
            return Err(spec_err(
                file,
                "base",
                "give a scenario file path (relative to the spec) or an inline scenario object",
            ))
        }
    };
    if !base.is_object() {
        return Err(spec_err(
            file,
            "base",
            "the base scenario must be a JSON object",
        ));
    }
    for (ptr, v) in &spec.set {
        pointer::set(&mut base, ptr, v.clone()).map_err(|m| spec_err(file, "set", m))?;
    }

    // Parameters: names, values, groups (axes of the grid).
    let mut parameters = Vec::new();
    let mut values: Vec<Vec<Value>> = Vec::new();
    for (k, p) in spec.parameters.iter().enumerate() {
        let field = format!("parameters[{k}]");
        pointer::tokens(&p.path).map_err(|m| spec_err(file, format!("{field}.path"), m))?;
        let name = p.name.clone().unwrap_or_else(|| p.path.clone());
        if name.is_empty() {
            return Err(spec_err(file, format!("{field}.name"), "must not be empty"));
        }
        if RESERVED_NAMES.contains(&name.as_str()) {
            return Err(spec_err(
                file,
                format!("{field}.name"),
                format!(
                    "'{name}' is a column of merged.csv already ({}); choose another",
                    RESERVED_NAMES.join(", ")
                ),
            ));
        }
        if let Some(j) = parameters.iter().position(|q: &Parameter| q.name == name) {
            return Err(spec_err(
                file,
                format!("{field}.name"),
                format!("'{name}' is already the name of parameters[{j}]"),
            ));
        }
        if let Some(j) = spec.parameters[..k].iter().position(|q| q.path == p.path) {
            return Err(spec_err(
                file,
                format!("{field}.path"),
                format!("'{}' is already set by parameters[{j}]", p.path),
            ));
        }
        let vals = match (&p.values, &p.range) {
            (Some(v), None) => {
                if v.is_empty() {
                    return Err(spec_err(
                        file,
                        format!("{field}.values"),
                        "is empty: give at least one value",
                    ));
                }
                v.clone()
            }
            (None, Some(r)) => {
                range_values(r).map_err(|m| spec_err(file, format!("{field}.range"), m))?
            }
            (Some(_), Some(_)) => {
                return Err(spec_err(file, field, "give 'values' or 'range', not both"))
            }
            (None, None) => {
                return Err(spec_err(
                    file,
                    field,
                    "give 'values' (a list) or 'range' (start, stop, step or count)",
                ))
            }
        };
        if spec.mode == Mode::Zip && p.group.is_some() {
            return Err(spec_err(
                file,
                format!("{field}.group"),
                "has no meaning with \"mode\": \"zip\" (all parameters are zipped already)",
            ));
        }
        parameters.push(Parameter {
            name,
            path: p.path.clone(),
        });
        values.push(vals);
    }
    // Axes: lists of parameter indices that move together, in order of first appearance.
    let mut axes: Vec<(Option<String>, Vec<usize>)> = Vec::new();
    for (k, p) in spec.parameters.iter().enumerate() {
        let key = match spec.mode {
            Mode::Zip => Some(String::new()),
            Mode::Grid => p.group.clone(),
        };
        match axes.iter_mut().find(|(g, _)| key.is_some() && *g == key) {
            Some((_, members)) => {
                let first = members[0];
                if values[k].len() != values[first].len() {
                    let what = match spec.mode {
                        Mode::Zip => "zipped with".to_string(),
                        Mode::Grid => {
                            format!("in group '{}' with", key.clone().unwrap_or_default())
                        }
                    };
                    return Err(spec_err(
                        file,
                        format!("parameters[{k}]"),
                        format!(
                            "has {} values but is {what} parameters[{first}], which has {}",
                            values[k].len(),
                            values[first].len()
                        ),
                    ));
                }
                members.push(k);
            }
            None => axes.push((key, vec![k])),
        }
    }
    let lens: Vec<usize> = axes.iter().map(|(_, m)| values[m[0]].len()).collect();
    let total = lens.iter().try_fold(1usize, |acc, &n| {
        acc.checked_mul(n).filter(|&t| t <= MAX_RUNS)
    });
    let Some(total) = total else {
        return Err(spec_err(
            file,
            "parameters",
            format!("the grid {lens:?} has more than {MAX_RUNS} runs"),
        ));
    };

    let label_base = file
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let mut runs: Vec<PlannedRun> = Vec::with_capacity(total);
    let mut by_id: BTreeMap<String, usize> = BTreeMap::new();
    for index in 0..total {
        // Mixed-radix digits of `index`, the last axis fastest.
        let mut pick = vec![0usize; parameters.len()];
        let mut rest = index;
        for ((_, members), &n) in axes.iter().zip(&lens).rev() {
            for &m in members {
                pick[m] = rest % n;
            }
            rest /= n;
        }
        let mut sc = base.clone();
        let mut vals = Vec::with_capacity(parameters.len());
        for (k, p) in parameters.iter().enumerate() {
            let v = values[k][pick[k]].clone();
            pointer::set(&mut sc, &p.path, v.clone())
                .map_err(|m| spec_err(file, format!("parameters[{k}].path"), m))?;
            vals.push(v);
        }
        let id = id::run_id(&sc);
        if let Some(&other) = by_id.get(&id) {
            return Err(spec_err(
                file,
                "parameters",
                format!("runs {other} and {index} expand to the same scenario (id {id}): a value is repeated"),
            ));
        }
        by_id.insert(id.clone(), index);
        runs.push(PlannedRun {
            index,
            id,
            values: vals,
            scenario: Ok(sc),
            label: format!("{label_base} run {index}"),
        });
    }
    Ok(Batch {
        description: spec.description.clone(),
        base_dir,
        parameters,
        runs,
    })
}

/// Rounds to 12 significant digits, so that a range from 0.2 in steps of 0.2 reads 0.6, not
/// 0.6000000000000001 (the noise of binary floating point, not a value anyone asked for).
fn round12(x: f64) -> f64 {
    format!("{x:.11e}").parse().unwrap_or(x)
}

/// The values of a range.
pub fn range_values(r: &RangeSpec) -> Result<Vec<Value>, String> {
    if !r.start.is_finite() || !r.stop.is_finite() {
        return Err(format!(
            "start {} and stop {} must be finite",
            r.start, r.stop
        ));
    }
    let xs: Vec<f64> = match (r.step, r.count) {
        (Some(step), None) => {
            if !step.is_finite() || step == 0.0 {
                return Err(format!("step {step} must be a finite number other than 0"));
            }
            let span = (r.stop - r.start) / step;
            if span < -1e-9 {
                return Err(format!(
                    "step {step} leads away from stop {} (start {}): flip its sign",
                    r.stop, r.start
                ));
            }
            let n = (span + 1e-9).floor() as usize + 1;
            if n > MAX_RUNS {
                return Err(format!("{n} values, more than {MAX_RUNS}"));
            }
            (0..n).map(|k| round12(r.start + k as f64 * step)).collect()
        }
        (None, Some(count)) => match count {
            0 => return Err("count 0: give at least 1".into()),
            1 if r.start != r.stop => {
                return Err(format!(
                    "count 1 cannot span {}..{}: give count >= 2",
                    r.start, r.stop
                ))
            }
            1 => vec![r.start],
            n if n > MAX_RUNS => return Err(format!("count {n} is more than {MAX_RUNS}")),
            n => (0..n)
                .map(|k| {
                    if k == n - 1 {
                        r.stop
                    } else {
                        round12(r.start + (r.stop - r.start) * k as f64 / (n - 1) as f64)
                    }
                })
                .collect(),
        },
        (Some(_), Some(_)) => return Err("give 'step' or 'count', not both".into()),
        (None, None) => return Err("give 'step' or 'count'".into()),
    };
    Ok(xs.into_iter().map(Value::from).collect())
}

/// A folder batch: each `*.json` file of `dir` (not sub-folders), sorted by name, is one run,
/// with one parameter, `file`.
pub fn load_folder(dir: &Path) -> Result<Batch, BatchError> {
    let io = |source| BatchError::Io {
        path: dir.to_path_buf(),
        source,
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(io)?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()
        .map_err(io)?;
    files.retain(|p| p.is_file() && p.extension().and_then(|e| e.to_str()) == Some("json"));
    files.sort();
    if files.is_empty() {
        return Err(spec_err(
            dir,
            ".",
            "the folder holds no *.json scenario file",
        ));
    }
    let mut runs: Vec<PlannedRun> = Vec::new();
    let mut by_id: BTreeMap<String, String> = BTreeMap::new();
    for (index, p) in files.iter().enumerate() {
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        let bytes = std::fs::read(p).map_err(|source| BatchError::Io {
            path: p.clone(),
            source,
        })?;
        let (id, scenario) = match serde_json::from_slice::<Value>(&bytes) {
            Ok(v) => (id::run_id(&v), Ok(v)),
            Err(e) => (
                id::bytes_id(&bytes),
                Err(format!("{}: not valid JSON: {e}", p.display())),
            ),
        };
        if let Some(other) = by_id.get(&id) {
            return Err(spec_err(
                dir,
                name,
                format!("holds the same scenario as {other} (id {id})"),
            ));
        }
        by_id.insert(id.clone(), name.clone());
        runs.push(PlannedRun {
            index,
            id,
            values: vec![Value::String(name)],
            scenario,
            label: p.display().to_string(),
        });
    }
    Ok(Batch {
        description: None,
        base_dir: dir.to_path_buf(),
        parameters: vec![Parameter {
            name: "file".into(),
            path: String::new(),
        }],
        runs,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn expand_json(spec: Value) -> Result<Batch, BatchError> {
        expand_text(&spec.to_string(), Path::new("spec.json"), Path::new("."))
    }

    fn base() -> Value {
        json!({"duration_s": 0.01, "apples": [{"diameter_m": 0.08, "velocity_m_s": [0, 0, -1], "position_m": [0, 0, 0.0401]}],
               "output": {}, "contact": {"friction": 0.3}})
    }

    fn col(b: &Batch, k: usize) -> Vec<Value> {
        b.runs.iter().map(|r| r.values[k].clone()).collect()
    }

    #[test]
    fn grid_first_parameter_slowest() {
        let b = expand_json(json!({"base": base(), "parameters": [
            {"name": "v", "path": "/apples/0/velocity_m_s/2", "values": [-1, -2]},
            {"name": "d", "path": "/apples/0/diameter_m", "values": [0.06, 0.08, 0.1]}]}))
        .unwrap();
        assert_eq!(b.runs.len(), 6);
        assert_eq!(
            col(&b, 0),
            vec![
                json!(-1),
                json!(-1),
                json!(-1),
                json!(-2),
                json!(-2),
                json!(-2)
            ]
        );
        assert_eq!(
            col(&b, 1),
            vec![
                json!(0.06),
                json!(0.08),
                json!(0.1),
                json!(0.06),
                json!(0.08),
                json!(0.1)
            ]
        );
        let sc = b.runs[4].scenario.as_ref().unwrap();
        assert_eq!(sc["apples"][0]["velocity_m_s"], json!([0, 0, -2]));
        assert_eq!(sc["apples"][0]["diameter_m"], json!(0.08));
        assert_eq!(
            b.runs.iter().map(|r| r.index).collect::<Vec<_>>(),
            (0..6).collect::<Vec<_>>()
        );
        assert_eq!(
            b.parameters[1],
            Parameter {
                name: "d".into(),
                path: "/apples/0/diameter_m".into()
            }
        );
    }

    #[test]
    fn groups_zip_inside_a_grid_and_mode_zip_zips_all() {
        let b = expand_json(json!({"base": base(), "parameters": [
            {"path": "/apples/0/velocity_m_s/2", "values": [-1, -2]},
            {"path": "/apples/0/diameter_m", "values": [0.06, 0.1], "group": "size"},
            {"path": "/apples/0/position_m/2", "values": [0.0301, 0.0501], "group": "size"}]}))
        .unwrap();
        assert_eq!(b.runs.len(), 4);
        assert_eq!(
            b.parameters[0].name, "/apples/0/velocity_m_s/2",
            "default name is the path"
        );
        for r in &b.runs {
            let d = r.values[1].as_f64().unwrap();
            let z = r.values[2].as_f64().unwrap();
            assert!(
                (z - (d / 2.0 + 1e-4)).abs() < 1e-12,
                "group members move together"
            );
        }
        let z = expand_json(json!({"base": base(), "mode": "zip", "parameters": [
            {"path": "/apples/0/velocity_m_s/2", "values": [-1, -2, -3]},
            {"path": "/apples/0/diameter_m", "values": [0.06, 0.08, 0.1]}]}))
        .unwrap();
        assert_eq!(z.runs.len(), 3);
        assert_eq!(col(&z, 1), vec![json!(0.06), json!(0.08), json!(0.1)]);
        let e = expand_json(json!({"base": base(), "mode": "zip", "parameters": [
            {"path": "/apples/0/velocity_m_s/2", "values": [-1, -2, -3]},
            {"path": "/apples/0/diameter_m", "values": [0.06, 0.08]}]}))
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("parameters[1]: has 2 values but is zipped with parameters[0], which has 3"),
            "{e}"
        );
        let e = expand_json(json!({"base": base(), "parameters": [
            {"path": "/apples/0/diameter_m", "values": [0.06, 0.08], "group": "g"},
            {"path": "/duration_s", "values": [1, 2, 3], "group": "g"}]}))
        .unwrap_err()
        .to_string();
        assert!(e.contains("in group 'g'"), "{e}");
    }

    #[test]
    fn ranges_by_step_and_count() {
        let r = |start, stop, step: Option<f64>, count: Option<usize>| {
            range_values(&RangeSpec {
                start,
                stop,
                step,
                count,
            })
        };
        let v = r(-0.2, -1.4, Some(-0.2), None).unwrap();
        assert_eq!(
            v,
            [-0.2, -0.4, -0.6, -0.8, -1.0, -1.2, -1.4]
                .map(Value::from)
                .to_vec()
        );
        let v = r(0.0, 1.0, None, Some(5)).unwrap();
        assert_eq!(v, [0.0, 0.25, 0.5, 0.75, 1.0].map(Value::from).to_vec());
        let v = r(0.1, 0.35, Some(0.1), None).unwrap();
        assert_eq!(
            v,
            [0.1, 0.2, 0.3].map(Value::from).to_vec(),
            "stop not on a step: the last step below it"
        );
        assert_eq!(r(2.0, 2.0, None, Some(1)).unwrap(), vec![Value::from(2.0)]);
        assert!(r(0.0, 1.0, Some(-0.1), None)
            .unwrap_err()
            .contains("flip its sign"));
        assert!(r(0.0, 1.0, Some(0.0), None).is_err());
        assert!(r(0.0, 1.0, Some(0.1), Some(3))
            .unwrap_err()
            .contains("not both"));
        assert!(r(0.0, 1.0, None, None).is_err());
        assert!(r(0.0, 1.0, None, Some(0)).is_err());
        assert!(r(0.0, 1.0, None, Some(1)).is_err());
        let e = expand_json(json!({"base": base(), "parameters": [
            {"path": "/duration_s", "range": {"start": 0, "stop": 1, "step": -1}}]}))
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("spec.json: parameters[0].range: step -1 leads away"),
            "{e}"
        );
    }

    #[test]
    fn bad_specs_name_the_field() {
        let cases = [
            (json!({"base": base(), "parameters": [{"path": "/apples/2/diameter_m", "values": [1]}]}),
             "parameters[0].path: '/apples/2/diameter_m': '/apples' has 1 element(s), no index 2"),
            (json!({"base": base(), "parameters": [{"path": "apples", "values": [1]}]}), "parameters[0].path"),
            (json!({"base": base(), "parameters": [{"path": "/duration_s"}]}), "parameters[0]: give 'values'"),
            (json!({"base": base(), "parameters": [{"path": "/duration_s", "values": []}]}), "parameters[0].values: is empty"),
            (json!({"base": base(), "parameters": [{"path": "/duration_s", "values": [1], "range": {"start": 0, "stop": 1, "count": 2}}]}), "not both"),
            (json!({"base": base(), "parameters": [{"path": "/duration_s", "values": [1], "nmae": "x"}]}), "parameters[0].nmae: unknown field `nmae`"),
            (json!({"base": base(), "parameters": [{"name": "id", "path": "/duration_s", "values": [1]}]}), "parameters[0].name: 'id' is a column"),
            (json!({"base": base(), "parameters": [{"name": "a", "path": "/duration_s", "values": [1]}, {"name": "a", "path": "/contact/friction", "values": [1]}]}), "parameters[1].name: 'a' is already"),
            (json!({"base": base(), "parameters": [{"path": "/duration_s", "values": [1]}, {"name": "b", "path": "/duration_s", "values": [2]}]}), "parameters[1].path: '/duration_s' is already set"),
            (json!({"base": base(), "parameters": [{"path": "/duration_s", "values": [1, 1]}]}), "runs 0 and 1 expand to the same scenario"),
            (json!({"base": base(), "set": {"/surfaces/0/material": "x"}}), "set: '/surfaces/0/material': the scenario has no field 'surfaces'"),
            (json!({"base": 3}), "base: give a scenario file path"),
            (json!({"base": "no_such_file.json"}), "base: cannot read"),
            (json!({"base": base(), "mode": "zip", "parameters": [{"path": "/duration_s", "values": [1], "group": "g"}]}), "parameters[0].group"),
            (json!({"base": base(), "mode": "diagonal"}), "mode: unknown variant `diagonal`"),
            (json!({"parameters": []}), "missing field `base`"),
        ];
        for (spec, want) in cases {
            let e = expand_json(spec.clone()).unwrap_err().to_string();
            assert!(
                e.contains(want),
                "spec {spec}\n  error: {e}\n  wanted: {want}"
            );
            assert!(e.starts_with("spec.json: "), "{e}");
        }
    }

    #[test]
    fn set_applies_to_every_run_and_no_parameters_is_one_run() {
        let b = expand_json(
            json!({"base": base(), "set": {"/output/force_history": false, "/duration_s": 0.02}}),
        )
        .unwrap();
        assert_eq!(b.runs.len(), 1);
        let sc = b.runs[0].scenario.as_ref().unwrap();
        assert_eq!(sc["output"]["force_history"], json!(false));
        assert_eq!(sc["duration_s"], json!(0.02));
    }

    #[test]
    fn ids_do_not_depend_on_parameter_order_or_position() {
        let a = expand_json(json!({"base": base(), "parameters": [
            {"path": "/apples/0/velocity_m_s/2", "values": [-1, -2]},
            {"path": "/apples/0/diameter_m", "values": [0.06, 0.1]}]}))
        .unwrap();
        let b = expand_json(json!({"base": base(), "parameters": [
            {"path": "/apples/0/diameter_m", "values": [0.1, 0.06]},
            {"path": "/apples/0/velocity_m_s/2", "values": [-2, -1, -3]}]}))
        .unwrap();
        let ids_a: std::collections::BTreeSet<_> = a.runs.iter().map(|r| r.id.clone()).collect();
        let ids_b: std::collections::BTreeSet<_> = b.runs.iter().map(|r| r.id.clone()).collect();
        assert!(
            ids_a.is_subset(&ids_b),
            "a grown, reordered sweep finds the same runs"
        );
        assert_eq!(ids_b.len() - ids_a.len(), 2);
    }
}
