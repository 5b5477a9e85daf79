//! Reading a run folder's files for the viewer: every malformed or truncated file is a
//! [`ViewError`] naming it.

use super::*;

pub(super) fn require(run_dir: &Path, name: &str, why: &'static str) -> Result<PathBuf, ViewError> {
    let p = crate::output::csv_file::locate(run_dir, name);
    if p.is_file() {
        Ok(p)
    } else {
        Err(ViewError::Missing { path: p, why })
    }
}

/// Column index of `name` in a header, or an error naming the file.
pub(super) fn column(
    path: &Path,
    header: &csv::StringRecord,
    name: &str,
) -> Result<usize, ViewError> {
    header.iter().position(|h| h == name).ok_or_else(|| {
        bad(
            path,
            format!("no column '{name}' in the header: not a file of an applesim run"),
        )
    })
}

/// A CSV reader of `path`, plain or gzipped ([`crate::output::csv_file::open`]).
pub(super) fn csv_reader(path: &Path) -> Result<csv::Reader<CsvInput>, ViewError> {
    let (_, f) = crate::output::csv_file::open(path).map_err(io(path))?;
    Ok(csv::ReaderBuilder::new().has_headers(true).from_reader(f))
}

/// A run's CSV file open for reading, plain or gzipped.
pub(super) type CsvInput = crate::output::csv_file::Input;

/// A run's CSV file and its header; an empty file (no header: the run was stopped before it
/// wrote it, or the file was cut) is refused naming it.
pub(super) fn open_csv(
    path: &Path,
) -> Result<(csv::Reader<CsvInput>, csv::StringRecord), ViewError> {
    let mut r = csv_reader(path)?;
    let h = r.headers().map_err(|e| csv_err(path, e))?.clone();
    if h.is_empty() || h.iter().all(|x| x.is_empty()) {
        return Err(bad(
            path,
            "empty file: the run was stopped before it wrote it, or the file was cut",
        ));
    }
    Ok((r, h))
}

pub(super) fn csv_err(path: &Path, e: csv::Error) -> ViewError {
    let line = e.position().map(|p| p.line());
    let msg = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!(
            "{len} fields where the header has {expected_len}: the file is truncated or damaged"
        ),
        _ => e.to_string(),
    };
    match line {
        Some(l) => bad(path, format!("line {l}: {msg}")),
        None => bad(path, msg),
    }
}

pub(super) fn num(path: &Path, line: u64, col: &str, s: &str) -> Result<f64, ViewError> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| bad(path, format!("line {line}: {col} = '{s}' is not a finite number: the file is truncated or damaged")))
}

pub(super) fn opt_num(
    path: &Path,
    line: u64,
    col: &str,
    s: &str,
) -> Result<Option<f64>, ViewError> {
    if s.trim().is_empty() {
        Ok(None)
    } else {
        num(path, line, col, s).map(Some)
    }
}

pub(super) fn point(path: &Path, line: u64, col: &str, s: &str) -> Result<[f64; 3], ViewError> {
    let v: Vec<&str> = s.split_whitespace().collect();
    if v.len() != 3 {
        return Err(bad(
            path,
            format!("line {line}: {col} = '{s}' is not three numbers"),
        ));
    }
    Ok([
        num(path, line, col, v[0])?,
        num(path, line, col, v[1])?,
        num(path, line, col, v[2])?,
    ])
}

pub(super) fn body_cols(path: &Path, h: &csv::StringRecord) -> Result<BodyCols, ViewError> {
    let c = |n: &str| column(path, h, n);
    Ok(BodyCols {
        t: c("time_s")?,
        apple: c("apple")?,
        p: [c("x_m")?, c("y_m")?, c("z_m")?],
        v: [c("vx_m_s")?, c("vy_m_s")?, c("vz_m_s")?],
        f: [c("fx_n")?, c("fy_n")?, c("fz_n")?],
        slip: c("slip_m_s")?,
        d: c("diameter_m")?,
        m: c("mass_kg")?,
        shape: shape_cols(h),
    })
}

/// The shape columns of a run with spheroids (`height_m`, `qw`, `qx`, `qy`, `qz`, issue 29),
/// when the header has them all; a run of spheres has none.
fn shape_cols(h: &csv::StringRecord) -> Option<[usize; 5]> {
    let at = |n: &str| h.iter().position(|x| x == n);
    let c = crate::output::BODIES_SHAPE_HEADER;
    Some([at(c[0])?, at(c[1])?, at(c[2])?, at(c[3])?, at(c[4])?])
}

/// A row's height (m) and orientation as a unit quaternion x y z w (three.js's order), from the
/// shape columns `cols`. `bodies.csv` prints the quaternion to a few digits: it is normalised
/// here, and one that cannot be (zero, or not finite) is refused naming the line.
pub(super) fn shape_of(
    path: &Path,
    line: u64,
    cols: &[usize; 5],
    rec: &csv::StringRecord,
) -> Result<(f64, [f64; 4]), ViewError> {
    let c = crate::output::BODIES_SHAPE_HEADER;
    let h = num(path, line, c[0], &rec[cols[0]])?;
    if h <= 0.0 {
        return Err(bad(
            path,
            format!("line {line}: height_m = {h} is not a size: the file is damaged"),
        ));
    }
    let [w, x, y, z] = [1, 2, 3, 4].map(|k| num(path, line, c[k], &rec[cols[k]]));
    let q = [x?, y?, z?, w?];
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(n > 0.5 && n < 2.0) {
        return Err(bad(
            path,
            format!("line {line}: the orientation (qw, qx, qy, qz) has norm {n}, not 1: the file is damaged"),
        ));
    }
    Ok((h, q.map(|v| v / n)))
}

pub(super) fn scan_bodies(path: &Path) -> Result<(BodiesScan, BodyCols), ViewError> {
    let (mut r, h) = open_csv(path)?;
    let cols = body_cols(path, &h)?;
    let mut s = BodiesScan {
        times: Vec::new(),
        apples: Vec::new(),
        index: HashMap::new(),
        lo: Vec3::splat(f64::INFINITY),
        hi: Vec3::splat(f64::NEG_INFINITY),
        max_speed: 0.0,
        max_force: 0.0,
        has_slip: false,
        last_names: Vec::new(),
    };
    // Apples in the sample being read: the run never removes an apple, so a sample with fewer
    // than the one before it is a file that lost rows.
    let (mut in_sample, mut before) = (0usize, 0usize);
    let mut rec = csv::StringRecord::new();
    loop {
        match r.read_record(&mut rec) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_err(path, e)),
        }
        let line = rec.position().map_or(0, |p| p.line());
        let t = num(path, line, "time_s", &rec[cols.t])?;
        match s.times.last() {
            Some(&last) if t == last => {}
            Some(&last) if t < last => {
                return Err(bad(
                    path,
                    format!("line {line}: time_s = {t} goes back from {last}: not in time order"),
                ))
            }
            last => {
                if let Some(&last) = last {
                    if in_sample < before {
                        return Err(bad(
                            path,
                            format!(
                                "the sample at t = {last} s has {in_sample} apples where the one before it has {before}: rows are missing, the file is damaged"
                            ),
                        ));
                    }
                }
                before = in_sample;
                in_sample = 0;
                s.last_names.clear();
                s.times.push(t)
            }
        }
        in_sample += 1;
        let name = &rec[cols.apple];
        s.last_names.push(name.to_string());
        let p = Vec3::new(
            num(path, line, "x_m", &rec[cols.p[0]])?,
            num(path, line, "y_m", &rec[cols.p[1]])?,
            num(path, line, "z_m", &rec[cols.p[2]])?,
        );
        let v = Vec3::new(
            num(path, line, "vx_m_s", &rec[cols.v[0]])?,
            num(path, line, "vy_m_s", &rec[cols.v[1]])?,
            num(path, line, "vz_m_s", &rec[cols.v[2]])?,
        );
        let f = Vec3::new(
            num(path, line, "fx_n", &rec[cols.f[0]])?,
            num(path, line, "fy_n", &rec[cols.f[1]])?,
            num(path, line, "fz_n", &rec[cols.f[2]])?,
        );
        s.max_force = s.max_force.max(f.length());
        if !rec[cols.slip].trim().is_empty() {
            num(path, line, "slip_m_s", &rec[cols.slip])?;
            s.has_slip = true;
        }
        let d = num(path, line, "diameter_m", &rec[cols.d])?;
        let m = num(path, line, "mass_kg", &rec[cols.m])?;
        let shape = match &cols.shape {
            Some(c) => Some(shape_of(path, line, c, &rec)?),
            None => None,
        };
        if !s.index.contains_key(name) {
            s.index.insert(name.to_string(), s.apples.len() as u32);
            let mut a = AppleInfo::new(name, d, m);
            a.height_m = shape.map(|(h, _)| h);
            s.apples.push(a);
        }
        s.lo = s.lo.min(p);
        s.hi = s.hi.max(p);
        s.max_speed = s.max_speed.max(v.length());
    }
    if in_sample < before {
        return Err(bad(
            path,
            format!(
                "the last sample (t = {} s) has {in_sample} apples where the one before it has {before}: the file is truncated",
                s.times.last().copied().unwrap_or(0.0)
            ),
        ));
    }
    Ok((s, cols))
}

/// Evenly spaced sample indices, first and last included, at most `max` of them.
pub(super) fn pick_frames(samples: usize, max: usize) -> Vec<usize> {
    if samples <= max {
        return (0..samples).collect();
    }
    let mut v: Vec<usize> = (0..max)
        .map(|k| ((k as f64) * (samples - 1) as f64 / (max - 1) as f64).round() as usize)
        .collect();
    v.dedup();
    v
}

pub(super) fn b64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (c.get(1).copied().unwrap_or(0) as u32) << 8
            | c.get(2).copied().unwrap_or(0) as u32;
        out.push(A[(n >> 18) as usize & 63] as char);
        out.push(A[(n >> 12) as usize & 63] as char);
        out.push(if c.len() > 1 {
            A[(n >> 6) as usize & 63] as char
        } else {
            '='
        });
        out.push(if c.len() > 2 {
            A[n as usize & 63] as char
        } else {
            '='
        });
    }
    out
}

/// Quantises `x` in [lo, lo + 65535 step] to u16 (nearest).
pub(super) fn q16(x: f64, lo: f64, step: f64) -> u16 {
    if step <= 0.0 {
        return 0;
    }
    ((x - lo) / step).round().clamp(0.0, 65535.0) as u16
}

pub(super) fn motion_code(path: &Path, line: u64, s: &str) -> Result<u8, ViewError> {
    Ok(match s {
        "airborne" => motion::AIRBORNE,
        "sliding" => motion::SLIDING,
        "rolling" => motion::ROLLING,
        _ => {
            return Err(bad(
                path,
                format!("line {line}: unknown motion state '{s}'"),
            ))
        }
    })
}

pub(super) fn read_transitions(
    path: &Path,
    index: &HashMap<String, u32>,
) -> Result<HashMap<u32, Track>, ViewError> {
    let (mut r, h) = open_csv(path)?;
    let (ca, cf, ct, cti) = (
        column(path, &h, "apple")?,
        column(path, &h, "from")?,
        column(path, &h, "to")?,
        column(path, &h, "time_s")?,
    );
    let mut out: HashMap<u32, Track> = HashMap::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| csv_err(path, e))?;
        let line = rec.position().map_or(0, |p| p.line());
        let Some(&i) = index.get(&rec[ca]) else {
            continue;
        };
        let t = num(path, line, "time_s", &rec[cti])?;
        out.entry(i).or_default().push((
            t,
            motion_code(path, line, &rec[cf])?,
            motion_code(path, line, &rec[ct])?,
        ));
    }
    for v in out.values_mut() {
        v.sort_by(|x, y| x.0.total_cmp(&y.0));
    }
    Ok(out)
}

/// Most points of an embedded force curve (the peak always among them).
pub const CURVE_POINTS: usize = 64;

/// Most force curves embedded (the contacts over a threshold with the largest impacts first).
pub const MAX_CURVES: usize = 2000;

/// `x` to 5 significant digits.
pub(super) fn sig5(x: f64) -> serde_json::Value {
    let r: f64 = format!("{x:.4e}").parse().unwrap_or(x);
    serde_json::json!(r)
}

/// The force curves of `wanted` contacts (index -> last time kept) from forces.csv, thinned to
/// [`CURVE_POINTS`] (evenly spaced samples plus the largest force).
pub(super) fn read_curves(
    path: &Path,
    wanted: &BTreeMap<usize, f64>,
) -> Result<BTreeMap<usize, [Vec<serde_json::Value>; 2]>, ViewError> {
    let (mut r, h) = open_csv(path)?;
    let (cc, ct, cf) = (
        column(path, &h, "contact")?,
        column(path, &h, "time_s")?,
        column(path, &h, "force_n")?,
    );
    let mut raw: BTreeMap<usize, Vec<(f64, f64)>> = BTreeMap::new();
    let mut rec = csv::StringRecord::new();
    while r.read_record(&mut rec).map_err(|e| csv_err(path, e))? {
        let line = rec.position().map_or(0, |p| p.line());
        let k = contact_index(path, line, &rec[cc])?;
        let Some(&until) = wanted.get(&k) else {
            continue;
        };
        let t = num(path, line, "time_s", &rec[ct])?;
        if t > until {
            continue;
        }
        let f = num(path, line, "force_n", &rec[cf])?;
        raw.entry(k).or_default().push((t, f));
    }
    Ok(raw
        .into_iter()
        .map(|(k, v)| {
            let mut idx = pick_frames(v.len(), CURVE_POINTS - 1);
            if let Some(peak) = (0..v.len()).max_by(|&a, &b| v[a].1.total_cmp(&v[b].1)) {
                if !idx.contains(&peak) {
                    idx.push(peak);
                    idx.sort_unstable();
                }
            }
            (
                k,
                [
                    idx.iter().map(|&i| sig5(v[i].0)).collect(),
                    idx.iter().map(|&i| sig5(v[i].1)).collect(),
                ],
            )
        })
        .collect())
}

/// One row of `apple_contacts.csv`: one apple's side of a contact and what it did to the apple
/// (docs/damage.md section 7).
#[derive(Debug, Clone)]
pub(super) struct HitRow {
    /// The contact's index in contacts.csv.
    pub contact: usize,
    /// The apple.
    pub apple: String,
    /// Time of the peak force (s).
    pub t_peak_s: f64,
    /// Contact point at the peak force (m, world).
    pub point_m: [f64; 3],
    /// Energy the apple absorbed (J).
    pub absorbed_energy_j: f64,
    /// Velocity change of the apple over the impact (m/s).
    pub velocity_change_m_s: f64,
    /// Peak acceleration of the apple (g).
    pub peak_g: f64,
    /// This hit alone bruised the apple by its model.
    pub bruised: bool,
    /// The bruise site it landed in.
    pub site: Option<usize>,
    /// Its part of its site's bruise volume (mm^3; none for an onset model).
    pub volume_mm3: Option<f64>,
    /// Static thresholds exceeded ("" when none).
    pub exceeded: String,
}

impl HitRow {
    /// What the contact did to the apple for the marks: "bruise" when the hit alone bruised it,
    /// else the static thresholds it exceeded, "" when none.
    pub fn risk(&self) -> String {
        if self.bruised {
            "bruise".into()
        } else {
            self.exceeded.clone()
        }
    }
}

/// `apple_contacts.csv`: every apple's side of every contact (fruit only).
pub(super) fn read_apple_contacts(path: &Path) -> Result<Vec<HitRow>, ViewError> {
    let (mut r, h) = open_csv(path)?;
    let c = |n: &str| column(path, &h, n);
    let (cc, ca, ct, cp, ce, cv, cg, cb, cs, cvol, cx) = (
        c("contact")?,
        c("apple")?,
        c("t_peak_s")?,
        c("contact_point_m")?,
        c("absorbed_energy_j")?,
        c("velocity_change_m_s")?,
        c("peak_g")?,
        c("bruised")?,
        c("site")?,
        c("volume_mm3")?,
        c("exceeded")?,
    );
    let mut out = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| csv_err(path, e))?;
        let line = rec.position().map_or(0, |p| p.line());
        let bruised = match &rec[cb] {
            "true" => true,
            "false" => false,
            other => {
                return Err(bad(
                    path,
                    format!("line {line}: bruised = '{other}' is not true or false"),
                ))
            }
        };
        let site = match rec[cs].trim() {
            "" => None,
            s => Some(
                contact_index(path, line, s)
                    .map_err(|_| bad(path, format!("line {line}: site = '{s}' is not an index")))?,
            ),
        };
        out.push(HitRow {
            contact: contact_index(path, line, &rec[cc])?,
            apple: rec[ca].to_string(),
            t_peak_s: num(path, line, "t_peak_s", &rec[ct])?,
            point_m: point(path, line, "contact_point_m", &rec[cp])?,
            absorbed_energy_j: num(path, line, "absorbed_energy_j", &rec[ce])?,
            velocity_change_m_s: num(path, line, "velocity_change_m_s", &rec[cv])?,
            peak_g: num(path, line, "peak_g", &rec[cg])?,
            bruised,
            site,
            volume_mm3: opt_num(path, line, "volume_mm3", &rec[cvol])?,
            exceeded: rec[cx].to_string(),
        });
    }
    Ok(out)
}

/// One row of `bruises.csv`: a bruise site of an apple (docs/damage.md section 4).
#[derive(Debug, Clone)]
pub(super) struct SiteRow {
    /// The apple.
    pub apple: String,
    /// The site's index on the apple.
    pub site: usize,
    /// Where, in the apple's own frame (unit vector from its centre).
    pub direction: [f64; 3],
    /// First hit (s).
    pub first_hit_s: f64,
    /// Hits there.
    pub hits: usize,
    /// The transfer points of its hits, joined by "; ".
    pub transfer_points: String,
    /// Energy the apple absorbed there (J).
    pub absorbed_energy_j: f64,
    /// Whether it is a bruise.
    pub bruised: bool,
    /// Volume (mm^3).
    pub volume_mm3: Option<f64>,
    /// Surface area (mm^2).
    pub area_mm2: Option<f64>,
    /// Depth (mm).
    pub depth_mm: Option<f64>,
    /// Surface diameter (mm).
    pub diameter_mm: Option<f64>,
}

/// `bruises.csv`: the bruise sites of every apple.
pub(super) fn read_sites(path: &Path) -> Result<Vec<SiteRow>, ViewError> {
    let (mut r, h) = open_csv(path)?;
    let c = |n: &str| column(path, &h, n);
    let (ca, cs, cx, cy, cz, cf, ch, ct, ce, cb) = (
        c("apple")?,
        c("site")?,
        c("x")?,
        c("y")?,
        c("z")?,
        c("first_hit_s")?,
        c("hits")?,
        c("transfer_points")?,
        c("absorbed_energy_j")?,
        c("bruised")?,
    );
    let (cv, car, cd, cdi) = (
        c("volume_mm3")?,
        c("area_mm2")?,
        c("depth_mm")?,
        c("diameter_mm")?,
    );
    let mut out = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| csv_err(path, e))?;
        let line = rec.position().map_or(0, |p| p.line());
        let index = |col: &str, s: &str| -> Result<usize, ViewError> {
            s.trim()
                .parse()
                .map_err(|_| bad(path, format!("line {line}: {col} = '{s}' is not a count")))
        };
        let bruised = match &rec[cb] {
            "true" => true,
            "false" => false,
            other => {
                return Err(bad(
                    path,
                    format!("line {line}: bruised = '{other}' is not true or false"),
                ))
            }
        };
        out.push(SiteRow {
            apple: rec[ca].to_string(),
            site: index("site", &rec[cs])?,
            direction: [
                num(path, line, "x", &rec[cx])?,
                num(path, line, "y", &rec[cy])?,
                num(path, line, "z", &rec[cz])?,
            ],
            first_hit_s: num(path, line, "first_hit_s", &rec[cf])?,
            hits: index("hits", &rec[ch])?,
            transfer_points: rec[ct].to_string(),
            absorbed_energy_j: num(path, line, "absorbed_energy_j", &rec[ce])?,
            bruised,
            volume_mm3: opt_num(path, line, "volume_mm3", &rec[cv])?,
            area_mm2: opt_num(path, line, "area_mm2", &rec[car])?,
            depth_mm: opt_num(path, line, "depth_mm", &rec[cd])?,
            diameter_mm: opt_num(path, line, "diameter_mm", &rec[cdi])?,
        });
    }
    Ok(out)
}

/// `audit.csv` as the page shows it: its columns as written, the first (the transfer point) as
/// text, the others as numbers to 6 significant digits (an empty cell: null).
pub(super) fn read_audit_table(path: &Path) -> Result<AuditInfo, ViewError> {
    let (mut r, h) = open_csv(path)?;
    if h.get(0) != Some("transfer_point") {
        return Err(bad(
            path,
            "its first column is not transfer_point: not an audit.csv of an applesim run",
        ));
    }
    let mut rows = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| csv_err(path, e))?;
        let line = rec.position().map_or(0, |p| p.line());
        let mut row = vec![serde_json::json!(rec[0].to_string())];
        for (k, cell) in rec.iter().enumerate().skip(1) {
            row.push(match opt_num(path, line, &h[k], cell)? {
                Some(x) => sig6(x),
                None => serde_json::Value::Null,
            });
        }
        rows.push(row);
    }
    Ok(AuditInfo {
        columns: h.iter().map(String::from).collect(),
        rows,
    })
}

/// contacts.csv: one [`ContactInfo`] per row, with each apple's side from apple_contacts.csv
/// (`sides`, by (contact, apple); without it a contact over `default_threshold` N of impact
/// peak force marks), and the transfer points they name (contacts.csv `transfer_point`; none in
/// a run from before it was written).
pub(super) fn read_contacts(
    path: &Path,
    index: &HashMap<String, u32>,
    sides: Option<&HashMap<(usize, String), HitRow>>,
    default_threshold: f64,
) -> Result<(Vec<ContactInfo>, Vec<String>), ViewError> {
    let (mut r, h) = open_csv(path)?;
    let c = |n: &str| column(path, &h, n);
    let cid = c("impact_duration_s")?;
    let ctp = h.iter().position(|x| x == "transfer_point");
    let cit = h.iter().position(|x| x == "impact_t_peak_s");
    let (ca, cb, cs, ce, cp, ctpk, cpr, cpt, ci) = (
        c("a")?,
        c("b")?,
        c("t_start_s")?,
        c("t_end_s")?,
        c("peak_force_n")?,
        c("t_peak_s")?,
        c("max_pressure_pa")?,
        c("contact_point_m")?,
        c("impact_peak_force_n")?,
    );
    let mut out = Vec::new();
    let mut points: Vec<String> = Vec::new();
    let mut point_index: HashMap<String, i64> = HashMap::new();
    for (k, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| csv_err(path, e))?;
        let line = rec.position().map_or(0, |p| p.line());
        let Some(&a) = index.get(&rec[ca]) else {
            return Err(bad(
                path,
                format!(
                    "line {line}: apple '{}' is not in bodies.csv: the files are of different runs",
                    &rec[ca]
                ),
            ));
        };
        let b_apple = index.get(&rec[cb]).map_or(-1, |&i| i as i64);
        let impact = opt_num(path, line, "impact_peak_force_n", &rec[ci])?.unwrap_or(0.0);
        let side = |who: &str| sides.and_then(|m| m.get(&(k, who.to_string())).cloned());
        let risk = |who: &str| -> String {
            match sides {
                Some(m) => m
                    .get(&(k, who.to_string()))
                    .map(HitRow::risk)
                    .unwrap_or_default(),
                None if impact > default_threshold => "force".into(),
                None => String::new(),
            }
        };
        let tp = match ctp.map(|c| rec[c].trim()) {
            Some(t) if !t.is_empty() => *point_index.entry(t.to_string()).or_insert_with(|| {
                points.push(t.to_string());
                points.len() as i64 - 1
            }),
            _ => -1,
        };
        out.push(ContactInfo {
            a,
            b_apple,
            b: rec[cb].to_string(),
            t_start_s: num(path, line, "t_start_s", &rec[cs])?,
            t_end_s: opt_num(path, line, "t_end_s", &rec[ce])?,
            t_peak_s: num(path, line, "t_peak_s", &rec[ctpk])?,
            impact_n: impact,
            impact_duration_s: opt_num(path, line, "impact_duration_s", &rec[cid])?,
            peak_force_n: num(path, line, "peak_force_n", &rec[cp])?,
            max_pressure_pa: num(path, line, "max_pressure_pa", &rec[cpr])?,
            point_m: point(path, line, "contact_point_m", &rec[cpt])?,
            risk_a: risk(&rec[ca]),
            risk_b: if b_apple >= 0 {
                risk(&rec[cb])
            } else {
                String::new()
            },
            tp,
            carrier: -1,
            local_m: None,
            side_a: side(&rec[ca]),
            side_b: if b_apple >= 0 { side(&rec[cb]) } else { None },
            t_impact_s: match cit {
                Some(c) => opt_num(path, line, "impact_t_peak_s", &rec[c])?,
                None => None,
            },
        });
    }
    Ok((out, points))
}

/// A `contact` column's value: the contact's index in contacts.csv.
fn contact_index(path: &Path, line: u64, s: &str) -> Result<usize, ViewError> {
    s.parse().map_err(|_| {
        bad(
            path,
            format!("line {line}: contact = '{s}' is not an index"),
        )
    })
}

/// The free-turning rollers' angles at the page's frames, from `rollers.csv`: roller name (a
/// bed's rollers `BED/k`) -> angle turned since the start at each frame (rad).
pub(super) type RollerAngles = HashMap<String, Vec<f64>>;

/// The names of the free-turning rollers of a scenario, as the run names them (one per unit: a
/// bed's rollers `BED/k`), in scenario order.
fn free_roller_names(sc: &Scenario) -> Vec<String> {
    sc.surfaces
        .iter()
        .flat_map(|s| s.units())
        .filter_map(|u| match u {
            SurfaceSpec::Roller(r) if r.free_turning.is_some() => Some(r.name),
            _ => None,
        })
        .collect()
}

/// Reads `rollers.csv` (the free-turning rollers' spin per sample, [`crate::output::rollers`])
/// for the frames at `times` (sample times of bodies.csv, or the run's end time when it holds
/// none). Every free-turning roller of `sc` must have a row at every frame's time and every row
/// must name one of them: a file cut short (the last frame is the run's end) or of another run
/// is refused naming it, as a damaged row is, rather than drawn at wrong angles.
pub(super) fn read_rollers(
    path: &Path,
    times: &[f64],
    sc: &Scenario,
) -> Result<RollerAngles, ViewError> {
    let names = free_roller_names(sc);
    let mut out: RollerAngles = names
        .iter()
        .map(|n| (n.clone(), vec![f64::NAN; times.len()]))
        .collect();
    let (mut r, h) = open_csv(path)?;
    let c = |n: &str| column(path, &h, n);
    let (ct, cr, ca, cw, cv) = (
        c("time_s")?,
        c("roller")?,
        c("angle_rad")?,
        c("spin_rad_s")?,
        c("surface_speed_m_s")?,
    );
    let mut last = f64::NEG_INFINITY;
    let mut rec = csv::StringRecord::new();
    while r.read_record(&mut rec).map_err(|e| csv_err(path, e))? {
        let line = rec.position().map_or(0, |p| p.line());
        let t = num(path, line, "time_s", &rec[ct])?;
        if t < last {
            return Err(bad(
                path,
                format!("line {line}: time_s = {t} goes back from {last}: not in time order"),
            ));
        }
        last = t;
        let angle = num(path, line, "angle_rad", &rec[ca])?;
        num(path, line, "spin_rad_s", &rec[cw])?;
        num(path, line, "surface_speed_m_s", &rec[cv])?;
        let Some(v) = out.get_mut(&rec[cr]) else {
            return Err(bad(
                path,
                format!(
                    "line {line}: roller '{}' is not a free-turning roller of scenario.json: the files are of different runs",
                    &rec[cr]
                ),
            ));
        };
        // Frame times are sample times read from bodies.csv, printed as this file prints them:
        // the same numbers exactly.
        if let Ok(f) = times.binary_search_by(|x| x.total_cmp(&t)) {
            v[f] = angle;
        }
    }
    for n in &names {
        if let Some(f) = out[n].iter().position(|a| a.is_nan()) {
            return Err(bad(
                path,
                format!(
                    "no row of roller '{n}' at t = {} s (a sample of bodies.csv): the file is truncated, or of another run",
                    times[f]
                ),
            ));
        }
    }
    Ok(out)
}
