//! The paper's Figs. 1-7 built from their specs in `paper.json` ([`super::paper`]) by one
//! builder, [`build`]: run the batch, measure every run ([`super::measure`]), check it, draw it,
//! tabulate it.
//!
//! Figs. 1-5 are one apple hitting a flat; every run is compared with the reference integration
//! of its own impact ([`reference::integrate_impact`], built from the scenario as run: mass,
//! speed, materials, gravity), and the trends the paper describes are checked across the runs.
//! Fig. 5 measures the bottom layer's middle apple; Figs. 6-7 the slip-to-roll transition
//! against physics.md section 6. What differs between two figures (what the batch varies, which
//! checks, which columns, which notes) is data; this module only knows how to do each.

use super::check::{Check, Criterion, Unit};
use super::measure::{self, ImpactRun, RollRun};
use super::paper::{
    CheckSpec, Column, Direction, FigureSpec, ImpactSpec, Measure, Note, RollSpec, Runs, Sweep,
};
use super::reference::{self, Elastic};
use super::runs::{self, Executed, Run};
use super::{write_chart, Chart, Figure, Table, ValidateError};
use crate::chart::{LineChart, Series};
use std::path::PathBuf;

/// Tolerance of every comparison with a closed form or with our reference integration: 0.5 %.
/// At dt = 1e-5 s the impacts get 560-3900 steps, where symplectic Euler is within about 1e-5
/// of the exact solution (physics.md section 10), so 0.5 % leaves room only for real mistakes.
pub const CLOSED_FORM_TOLERANCE: f64 = 0.005;

/// Tolerance against the numbers the paper quotes: 4 % (the acceptance; physics.md
/// section 8 reproduces them within 3.1 % with m = 0.107 kg).
pub const PAPER_TOLERANCE: f64 = 0.04;

/// What the figure builders share: where specs are, where runs and charts go, and the charts
/// written so far (the validation returns them with the report).
#[derive(Debug)]
pub struct Context {
    /// Folder of the specs.
    pub specs_dir: PathBuf,
    /// Folder of the report and charts.
    pub out_dir: PathBuf,
    /// Folder of the runs.
    pub runs_dir: PathBuf,
    /// Runs at a time.
    pub jobs: usize,
    /// Charts written so far.
    pub written: Vec<PathBuf>,
}

impl Context {
    /// Runs the spec `name` (`fig1.json`) into `RUNS/<stem>/`.
    pub fn execute(&self, name: &str) -> Result<Executed, ValidateError> {
        let stem = name.trim_end_matches(".json");
        runs::execute(
            &self.specs_dir.join(name),
            &self.runs_dir.join(stem),
            self.jobs,
        )
    }

    /// The spec `name` as the report shows it.
    pub fn spec_label(&self, name: &str) -> String {
        self.specs_dir.join(name).display().to_string()
    }
}

/// Runs the figure `spec` describes and builds its section of the report: the runs measured,
/// a check per failed run and per claim, its charts, its table and notes.
pub fn build(ctx: &mut Context, spec: &FigureSpec) -> Result<Figure, ValidateError> {
    let ex = ctx.execute(&spec.spec)?;
    let mut figure = Figure {
        id: spec.id.clone(),
        title: spec.title.clone(),
        paper: spec.paper.clone(),
        spec: ctx.spec_label(&spec.spec),
        description: ex.description.clone(),
        charts: vec![],
        table: Table::default(),
        notes: vec![],
        checks: failed_runs(&spec.id, &ex),
        impacts: vec![],
        rolls: vec![],
    };
    match &spec.runs {
        Runs::Impacts(s) => impact_figure(ctx, &ex, s, &mut figure)?,
        Runs::Rolls(s) => roll_figure(ctx, &ex, s, &mut figure)?,
    }
    Ok(figure)
}

/// A check per failed run (the figure's other checks then cover fewer runs).
fn failed_runs(id: &str, ex: &Executed) -> Vec<Check> {
    ex.failed
        .iter()
        .map(|(k, label, error)| {
            Check::missing(
                format!("{id}/run/{k}"),
                format!("run {k} ({label}) completes"),
                format!("failed: {error}"),
            )
        })
        .collect()
}

impl Sweep {
    /// A run's legend and table label, from its batch parameters.
    fn label(self, r: &Run) -> String {
        let p = |name: &str| r.param(name);
        match self {
            Sweep::Speed => format!("v0 = {} m/s", -p("v0_m_s")),
            Sweep::SizeAndSpeed => format!(
                "D {} mm, v0 {} m/s",
                (p("diameter_m") * 1e3).round(),
                -p("v0_m_s")
            ),
            Sweep::AppleModulus => format!("G1 = {} MPa", p("apple_shear_modulus_pa") / 1e6),
            Sweep::PlatformModulus => {
                format!("G2 = {}", platform_name(p("platform_shear_modulus_pa")))
            }
            Sweep::LayersAndSpeed => format!(
                "{} layer{}, {} m/s",
                p("layers"),
                if p("layers") == 1.0 { "" } else { "s" },
                -p("v0_m_s")
            ),
            Sweep::Ke => format!("ke = {}", p("ke")),
            Sweep::Spin => format!("w0 = {} 1/s", p("w0_rad_s")),
            Sweep::LaunchSpeed => format!("v0 = {} m/s", p("v0_m_s")),
        }
    }

    /// The last part of an impact's check keys: stable, so tests can look a check up.
    fn case(self, i: &ImpactRun) -> String {
        match self {
            Sweep::SizeAndSpeed => format!("D{}/v{}", (i.diameter_m * 1e3).round(), i.v0_m_s),
            Sweep::AppleModulus => format!("G{}", i.apple_shear_modulus_pa / 1e6),
            Sweep::PlatformModulus => format!("G2_{}", modulus(i.platform_shear_modulus_pa)),
            Sweep::LayersAndSpeed => {
                format!("layers{}/v{}", i.param("layers"), self.speed(i))
            }
            Sweep::Ke => format!("ke{}", i.ke),
            Sweep::Speed | Sweep::Spin | Sweep::LaunchSpeed => format!("{}", i.v0_m_s),
        }
    }

    /// The speed an impact belongs to in a per-speed group: the touch speed, or in Fig. 5 the
    /// batch's landing speed (the apples touch slightly faster after their 0.1 mm fall).
    fn speed(self, i: &ImpactRun) -> f64 {
        match self {
            Sweep::LayersAndSpeed => -i.param("v0_m_s"),
            _ => i.v0_m_s,
        }
    }

    /// The value a trend runs along, when not the order of the runs.
    fn order(self) -> Option<fn(&ImpactRun) -> f64> {
        match self {
            Sweep::SizeAndSpeed => Some(|i| i.diameter_m),
            Sweep::PlatformModulus => Some(|i| i.platform_shear_modulus_pa),
            Sweep::LayersAndSpeed => Some(|i| i.param("layers")),
            _ => None,
        }
    }

    /// Whether an impact is one apple alone on the flat, which the reference integration
    /// describes: in Fig. 5 only with one layer, as then nothing presses from above.
    fn alone(self, i: &ImpactRun) -> bool {
        self != Sweep::LayersAndSpeed || i.param("layers") == 1.0
    }

    /// `impacts` in the order of the sweep (a stable sort: run order where it has none).
    fn sorted<'a>(self, impacts: &[&'a ImpactRun]) -> Vec<&'a ImpactRun> {
        let mut v = impacts.to_vec();
        if let Some(key) = self.order() {
            v.sort_by(|a, b| key(a).total_cmp(&key(b)));
        }
        v
    }
}

/// An impact figure (Figs. 1-5, and the eq. 12 batch behind errata 4-5).
fn impact_figure(
    ctx: &mut Context,
    ex: &Executed,
    s: &ImpactSpec,
    fig: &mut Figure,
) -> Result<(), ValidateError> {
    let impacts: Vec<ImpactRun> = ex
        .runs
        .iter()
        .map(|r| measure::impact(ex, r, &s.apple, &s.other, s.sweep.label(r)))
        .collect::<Result<_, _>>()?;
    let all: Vec<&ImpactRun> = impacts.iter().collect();
    for c in &s.checks {
        impact_checks(&fig.id, s.sweep, c, &all, None, &mut fig.checks);
    }
    let file = format!("{}_force.svg", fig.id);
    fig.charts = vec![force_chart(ctx, ex, &impacts, &file, &s.chart)?];
    if !s.columns.is_empty() {
        fig.table = Table {
            header: s.columns.iter().map(|(h, _)| h.clone()).collect(),
            rows: impacts
                .iter()
                .map(|i| s.columns.iter().map(|(_, c)| c.cell(i, &impacts)).collect())
                .collect(),
        };
    }
    for n in &s.notes {
        fig.notes.extend(n.text(&impacts));
    }
    fig.impacts = impacts;
    Ok(())
}

/// The checks `c` asks for over `impacts`; `speed` is the group's within [`CheckSpec::PerSpeed`].
fn impact_checks(
    id: &str,
    sweep: Sweep,
    c: &CheckSpec,
    impacts: &[&ImpactRun],
    speed: Option<f64>,
    out: &mut Vec<Check>,
) {
    match c {
        CheckSpec::Quoted { source } => quoted_checks(id, impacts, source, out),
        CheckSpec::Reference => {
            for i in impacts.iter().filter(|i| sweep.alone(i)) {
                let mut source = reference_source(i);
                if sweep == Sweep::LayersAndSpeed {
                    source.push_str(", one apple alone");
                }
                out.extend(reference_checks(id, &sweep.case(i), i, &source));
            }
        }
        CheckSpec::Trend {
            key,
            of,
            goes,
            up_to,
            what,
            source,
        } => {
            let mut along = sweep.sorted(impacts);
            if let Some(up_to) = up_to {
                along.retain(|i| sweep.order().is_some_and(|key| key(i) <= *up_to));
            }
            let ys: Vec<f64> = along
                .iter()
                .map(|i| match of {
                    Measure::PeakForce => i.peak_force_n,
                    Measure::ContactTime => i.contact_time_s,
                })
                .collect();
            let (key, what) = match speed {
                Some(v) => (
                    format!("{id}/trend/{key}/v{v}"),
                    what.replace("{v}", &v.to_string()),
                ),
                None => (format!("{id}/trend/{key}"), what.clone()),
            };
            out.push(trend(key, what, &ys, *goes, source));
        }
        CheckSpec::PerSpeed { checks } => {
            let mut speeds: Vec<f64> = impacts.iter().map(|i| sweep.speed(i)).collect();
            speeds.sort_by(f64::total_cmp);
            speeds.dedup();
            for v in speeds {
                let at: Vec<&ImpactRun> = impacts
                    .iter()
                    .copied()
                    .filter(|i| sweep.speed(i) == v)
                    .collect();
                let at = sweep.sorted(&at);
                for c in checks {
                    impact_checks(id, sweep, c, &at, Some(v), out);
                }
            }
        }
        CheckSpec::TimeFallsSlightly { limit, source } => {
            if let (Some(a), Some(b)) = (impacts.first(), impacts.last()) {
                let slope = (b.contact_time_s / a.contact_time_s).ln() / (b.v0_m_s / a.v0_m_s).ln();
                out.push(Check::bound(
                    format!("{id}/trend/time_falls_slightly"),
                    format!(
                        "contact time falls slightly: |d ln t / d ln v0| from {} to {} m/s",
                        a.v0_m_s, b.v0_m_s
                    ),
                    slope.abs(),
                    source,
                    Unit::Plain,
                    Criterion::Below { limit: *limit },
                ));
            }
        }
        CheckSpec::TimeLongerAtLowerSpeed { what, source } => {
            out.push(time_longer_at_lower_speed(id, impacts, what, source));
        }
        CheckSpec::PlatformAgainstSteel {
            stiff_from_pa,
            stiff_limit,
            stiff_source,
            soft_limit,
            soft_source,
        } => {
            let Some(steel) = steel(impacts.iter().copied()) else {
                return;
            };
            for i in sweep.sorted(impacts) {
                let change = i.peak_force_n / steel.peak_force_n - 1.0;
                let g2 = i.platform_shear_modulus_pa;
                if std::ptr::eq(i, steel) {
                    continue;
                }
                if g2 >= *stiff_from_pa {
                    out.push(Check::bound(
                        format!("{id}/stiff_platform/G2_{}", modulus(g2)),
                        format!("{}: size of the peak force change against steel", i.label),
                        change.abs(),
                        stiff_source,
                        Unit::Percent,
                        Criterion::Below {
                            limit: *stiff_limit,
                        },
                    ));
                } else if g2 <= i.apple_shear_modulus_pa {
                    out.push(Check::bound(
                        format!("{id}/soft_platform/G2_{}", modulus(g2)),
                        format!("{}: peak force reduction against steel", i.label),
                        -change,
                        soft_source,
                        Unit::Percent,
                        Criterion::AtLeast { limit: *soft_limit },
                    ));
                }
            }
        }
        CheckSpec::Restitution => {
            for i in impacts {
                out.extend(restitution_checks(id, i));
            }
        }
    }
}

/// Fig. 1: the two points the paper's text quotes, at [`PAPER_TOLERANCE`].
fn quoted_checks(id: &str, impacts: &[&ImpactRun], source: &str, out: &mut Vec<Check>) {
    for q in reference::FIG1_QUOTED {
        let Some(i) = impacts.iter().find(|i| (i.v0_m_s - q.v0_m_s).abs() < 1e-9) else {
            out.push(Check::missing(
                format!("{id}/paper/peak_force/{}", q.v0_m_s),
                format!("paper's quoted point at {} m/s", q.v0_m_s),
                "no run at this speed",
            ));
            continue;
        };
        out.extend(force_and_time(
            &format!("{id}/paper"),
            &format!("{}", q.v0_m_s),
            |what| format!("{what} at {} m/s", q.v0_m_s),
            i,
            (q.peak_force_n, q.contact_time_s),
            source,
            PAPER_TOLERANCE,
        ));
    }
}

/// Fig. 2: "at the lower collision rates, the interaction time is greater", for every size:
/// the smallest excess of the slowest run's contact time over the fastest's.
fn time_longer_at_lower_speed(id: &str, impacts: &[&ImpactRun], what: &str, source: &str) -> Check {
    let mut sizes: Vec<f64> = impacts.iter().map(|i| i.diameter_m).collect();
    sizes.sort_by(f64::total_cmp);
    sizes.dedup();
    let longer_when_slower = sizes.iter().filter_map(|&d| {
        let mut at: Vec<&&ImpactRun> = impacts.iter().filter(|i| i.diameter_m == d).collect();
        at.sort_by(|a, b| a.v0_m_s.total_cmp(&b.v0_m_s));
        let (slow, fast) = (at.first()?, at.last()?);
        (at.len() > 1).then(|| slow.contact_time_s / fast.contact_time_s - 1.0)
    });
    Check::bound(
        format!("{id}/trend/time_longer_at_lower_speed"),
        what,
        longer_when_slower.fold(f64::INFINITY, f64::min),
        source,
        Unit::Percent,
        Criterion::Above { limit: 0.0 },
    )
}

/// The eq. 12 batch: restitution against the integration of eq. 12 and against sqrt(ke); without
/// gravity also peak force and contact time against physics.md section 3 (for lambda v0 >> 1:
/// the elastic peak force, contact time t_H / 2 (1 + 1/sqrt(ke)); exact without gravity).
fn restitution_checks(id: &str, i: &ImpactRun) -> Vec<Check> {
    let lv = i.lambda_s_m * i.v0_m_s;
    let mut checks = vec![
        Check::relative(
            format!("{id}/restitution/ke{}", i.ke),
            format!("restitution at ke = {}", i.ke),
            i.restitution,
            i.reference.restitution(i.v0_m_s),
            format!("RK4 of eq. 12 (dissipative sign), lambda v0 = {lv}"),
            Unit::Plain,
            CLOSED_FORM_TOLERANCE,
        ),
        Check::relative(
            format!("{id}/closed_form/restitution/ke{}", i.ke),
            format!("restitution at ke = {}", i.ke),
            i.restitution,
            i.ke.sqrt(),
            format!("physics.md section 3: e = sqrt(ke) for lambda v0 >> 1 (here {lv})"),
            Unit::Plain,
            CLOSED_FORM_TOLERANCE,
        ),
    ];
    if i.gravity_m_s2 == 0.0 {
        checks.push(Check::relative(
            format!("{id}/closed_form/peak_force/ke{}", i.ke),
            format!("peak force at ke = {}", i.ke),
            i.peak_force_n,
            i.closed_form.peak_force_n,
            "physics.md sections 3-4: P_max of the elastic impact, no gravity",
            Unit::Newton,
            CLOSED_FORM_TOLERANCE,
        ));
        checks.push(Check::relative(
            format!("{id}/closed_form/contact_time/ke{}", i.ke),
            format!("contact time at ke = {}", i.ke),
            i.contact_time_s,
            0.5 * i.closed_form.contact_time_s * (1.0 + 1.0 / i.ke.sqrt()),
            "physics.md section 3: t_H / 2 (1 + 1/sqrt(ke)), no gravity",
            Unit::Millisecond,
            CLOSED_FORM_TOLERANCE,
        ));
    }
    checks
}

/// The peak-force and contact-time checks of one impact against its reference integration.
fn reference_checks(id: &str, case: &str, i: &ImpactRun, source: &str) -> [Check; 2] {
    force_and_time(
        &format!("{id}/reference"),
        case,
        |what| format!("{what}, {}", i.label),
        i,
        (i.reference.peak_force_n, i.reference.contact_time_s),
        source,
        CLOSED_FORM_TOLERANCE,
    )
}

/// Impact `i`'s peak force and contact time against `(peak force, contact time)`, keyed
/// `PREFIX/peak_force/CASE` and `PREFIX/contact_time/CASE`; `what` words each measure.
fn force_and_time(
    prefix: &str,
    case: &str,
    what: impl Fn(&str) -> String,
    i: &ImpactRun,
    against: (f64, f64),
    source: &str,
    tolerance: f64,
) -> [Check; 2] {
    [
        (
            "peak_force",
            "peak force",
            i.peak_force_n,
            against.0,
            Unit::Newton,
        ),
        (
            "contact_time",
            "contact time",
            i.contact_time_s,
            against.1,
            Unit::Millisecond,
        ),
    ]
    .map(|(key, measure, ours, reference, unit)| {
        Check::relative(
            format!("{prefix}/{key}/{case}"),
            what(measure),
            ours,
            reference,
            source,
            unit,
            tolerance,
        )
    })
}

/// How the report names the reference integration of an impact: the equation it integrates.
fn reference_source(i: &ImpactRun) -> String {
    if i.ke == 1.0 {
        if i.gravity_m_s2 != 0.0 {
            "RK4 of m u'' = m g - k u^1.5".into()
        } else {
            "RK4 of m u'' = -k u^1.5".into()
        }
    } else {
        "RK4 of eq. 12 (dissipative sign)".into()
    }
}

/// A trend check: `ys` rises (falls) at every step, held by the smallest (largest) relative
/// step `ys[i+1] / ys[i] - 1` between neighbours, which is > 0 (< 0) when it does.
fn trend(key: String, what: String, ys: &[f64], goes: Direction, source: &str) -> Check {
    let steps = ys.windows(2).map(|w| w[1] / w[0] - 1.0);
    let (worst, source, criterion) = match goes {
        Direction::Up => (
            steps.fold(f64::INFINITY, f64::min),
            format!("{source}; smallest rise between neighbours"),
            Criterion::Above { limit: 0.0 },
        ),
        Direction::Down => (
            steps.fold(f64::NEG_INFINITY, f64::max),
            format!("{source}; largest change between neighbours"),
            Criterion::Below { limit: 0.0 },
        ),
    };
    Check::bound(key, what, worst, source, Unit::Percent, criterion)
}

/// The run on the stiffest platform (steel in Fig. 4), the one the others are compared with.
fn steel<'a>(impacts: impl Iterator<Item = &'a ImpactRun>) -> Option<&'a ImpactRun> {
    impacts.max_by(|a, b| {
        a.platform_shear_modulus_pa
            .total_cmp(&b.platform_shear_modulus_pa)
    })
}

impl Column {
    /// The cell of impact `i` in a table of `all`.
    fn cell(self, i: &ImpactRun, all: &[ImpactRun]) -> String {
        match self {
            Column::TouchSpeed => format!("{}", i.v0_m_s),
            Column::TouchSpeed4 => fmt_sig(i.v0_m_s),
            Column::LaunchSpeed => format!("{}", -i.param("v0_m_s")),
            Column::Layers => format!("{}", i.param("layers")),
            Column::DiameterMm => format!("{}", (i.diameter_m * 1e3).round()),
            Column::Mass => format!("{:.6}", i.mass_kg)
                .trim_end_matches('0')
                .to_string(),
            Column::AppleModulusMpa => format!("{}", i.apple_shear_modulus_pa / 1e6),
            Column::Platform => platform_name(i.platform_shear_modulus_pa),
            Column::ModulusRatio => {
                fmt_g_ratio(i.platform_shear_modulus_pa / i.apple_shear_modulus_pa)
            }
            Column::PeakForce => newton(i.peak_force_n),
            Column::ContactTime => ms(i.contact_time_s),
            Column::OverlapPercent(digits) => format!(
                "{:.*} %",
                digits,
                100.0 * (i.max_overlap_m / (i.diameter_m / 2.0))
            ),
            Column::ChangeVsSteel => steel(all.iter()).map_or("-".into(), |s| {
                format!("{:+.2} %", 100.0 * (i.peak_force_n / s.peak_force_n - 1.0))
            }),
            Column::ReferencePeakForce => newton(i.reference.peak_force_n),
            Column::ReferenceContactTime => ms(i.reference.contact_time_s),
            Column::ClosedFormPeakForce => newton(i.closed_form.peak_force_n),
            Column::ClosedFormContactTime => ms(i.closed_form.contact_time_s),
            Column::Quoted => reference::FIG1_QUOTED
                .iter()
                .find(|q| (q.v0_m_s - i.v0_m_s).abs() < 1e-9)
                .map(|q| {
                    format!(
                        "{} N, {} ms",
                        q.peak_force_n,
                        ms(q.contact_time_s).trim_end_matches('0')
                    )
                })
                .unwrap_or_default(),
        }
    }
}

impl Note {
    /// The note's text over a figure's impacts (none when they lack what it needs).
    fn text(self, impacts: &[ImpactRun]) -> Option<String> {
        let first = impacts.first()?;
        Some(match self {
            Note::GravityEffect => format!(
                "Reference: our RK4 integration of the same impact with gravity (100 000 steps per contact; it reproduces physics.md's 11.18 N / 8.66 ms and 99.97 N / 5.63 ms, and the no-gravity closed form to 1e-9). The no-gravity closed form of physics.md section 4 is shown for comparison: at {} m/s gravity adds {:.1} % to the peak force and {:.1} % to the contact time.",
                first.v0_m_s,
                100.0 * (first.reference.peak_force_n / first.closed_form.peak_force_n - 1.0),
                100.0 * (first.reference.contact_time_s / first.closed_form.contact_time_s - 1.0)
            ),
            Note::ApproachSpeed => format!(
                "The simulator's approach speed is v0 + g dt (rapier applies gravity before it moves the apple in the first step): {:+.3} % at {} m/s, inside the tolerance.",
                100.0 * (first.approach_speed_m_s / first.v0_m_s - 1.0),
                first.v0_m_s
            ),
            Note::DeepestOverlap => format!(
                "Deepest overlap: {:.1} % of the radius (G2 = 1e4 Pa), inside the default guard model.max_overlap_ratio = 50 % but far from Hertz theory's u << R: the softest platforms are the model's answer, not a validated one.",
                100.0
                    * impacts
                        .iter()
                        .map(|i| i.max_overlap_m / (i.diameter_m / 2.0))
                        .fold(0.0f64, f64::max)
            ),
            Note::PlatformPoisson => {
                // How much the platforms' Poisson ratio (not given by the paper) matters at
                // G2 = G1.
                let s = steel(impacts.iter())?;
                let change = |nu2: f64| {
                    let a = Elastic::from_shear(first.apple_shear_modulus_pa, 0.18);
                    let p = Elastic::from_shear(first.apple_shear_modulus_pa, nu2);
                    let k = reference::flat_stiffness(a, p, first.diameter_m / 2.0);
                    let o = reference::elastic_impact_with_gravity(
                        first.mass_kg,
                        first.v0_m_s,
                        k,
                        first.gravity_m_s2,
                    );
                    o.peak_force_n / s.reference.peak_force_n - 1.0
                };
                format!(
                    "The platforms' Poisson ratio matters where they are soft: at G2 = G1 the reference integration gives {:+.1} % against steel with nu2 = 0.28 (ours), {:+.1} % with nu2 = 0.18 (the apple's) and {:+.1} % with nu2 = 0.45 (a rubber).",
                    100.0 * change(0.28),
                    100.0 * change(0.18),
                    100.0 * change(0.45)
                )
            }
            Note::LayersStay => format!(
                "The apples start 0.1 mm above the floor, so they touch it at sqrt(v0^2 + 2 g 0.1 mm), the touch speed above; the one-apple reference uses it. With more layers the upper apples arrive later through the soft apple-apple contacts and keep the bottom apple pressed: its contact lasts up to {:.1} times as long as alone, and its force rises.",
                impacts
                    .iter()
                    .map(|i| i.contact_time_s / i.reference.contact_time_s)
                    .fold(0.0, f64::max)
            ),
        })
    }
}

/// A slip-to-roll figure (Figs. 6-7): time to rolling and rolling speed against physics.md
/// section 6, the paper's 0.1 s bound, and the centre and angular speed charts.
fn roll_figure(
    ctx: &mut Context,
    ex: &Executed,
    s: &RollSpec,
    fig: &mut Figure,
) -> Result<(), ValidateError> {
    let id = fig.id.clone();
    let rolls: Vec<RollRun> = ex
        .runs
        .iter()
        .map(|r| measure::roll(ex, r, s.sweep.label(r)))
        .collect::<Result<_, _>>()?;
    for (run, rr) in ex.runs.iter().zip(&rolls) {
        let case = run
            .params
            .first()
            .map_or(String::new(), |(n, v)| format!("{n}{v}"));
        fig.checks.push(Check::bound(
            format!("{id}/paper/rolls_within_{}s/{case}", s.within_s),
            format!("{}: time to rolling", rr.label),
            rr.t_roll_s,
            format!("{}, mu = {}", s.source, rr.friction),
            Unit::Second,
            Criterion::Below { limit: s.within_s },
        ));
        let closed_forms = [
            (
                "time",
                "time to rolling",
                rr.t_roll_s,
                rr.closed.time_s,
                Unit::Millisecond,
            ),
            (
                "speed",
                "rolling speed",
                rr.rolling_speed_m_s,
                rr.closed.speed_m_s,
                Unit::MetrePerSecond,
            ),
        ];
        for (key, what, ours, closed, unit) in closed_forms {
            fig.checks.push(Check::relative(
                format!("{id}/closed_form/{key}/{case}"),
                format!("{}: {what}", rr.label),
                ours,
                closed,
                "physics.md section 6, lever R - u",
                unit,
                CLOSED_FORM_TOLERANCE,
            ));
        }
    }
    // Charts: centre speed and angular speed against time.
    let mut speed = Vec::new();
    let mut spin = Vec::new();
    for (run, rr) in ex.runs.iter().zip(&rolls) {
        let curves = crate::output::plot::read_run(&run.dir)?;
        if let Some((_, k)) = curves.apples.first() {
            speed.push(Series {
                label: rr.label.clone(),
                points: k.speed.clone(),
            });
            spin.push(Series {
                label: rr.label.clone(),
                points: k.spin.clone(),
            });
        }
    }
    for (suffix, what, y, series) in [
        ("speed", "centre speed", "centre speed |v| (m/s)", speed),
        ("spin", "angular speed", "angular speed |w| (rad/s)", spin),
    ] {
        let file = format!("{id}_{suffix}.svg");
        let caption = format!("{}: {what}", fig.title);
        let chart = LineChart::new(&caption, "time (s)", y, series);
        write_chart(ctx, &file, &chart)?;
        fig.charts.push(Chart { file, caption });
    }
    fig.table = roll_table(&rolls);
    fig.notes = vec![rolls.first().map_or(String::new(), |rr| format!(
        "The transition is where the slip speed of the contact point, v_x - (R - u) w_y, reaches zero, from bodies.csv sampled every 0.1 ms (linear through the last two sliding samples; R - u is the centre's height above the plate as run). The closed form's lever is R - u with u = (2 m g / ((1 + ke) k))^(2/3) = {:.4} mm, the resting sag under eq. 12, from the materials and mass alone: it is {:.2} % shorter than R, which changes the time to rolling by {:+.2} % against the textbook lever R ({}).",
        rr.resting_overlap_m * 1e3,
        100.0 * rr.resting_overlap_m / rr.radius_m,
        100.0 * (rr.closed.time_s / rr.closed_plain.time_s - 1.0),
        rr.label
    ))];
    fig.rolls = rolls;
    Ok(())
}

/// The table of a slip-to-roll figure: measured against both closed forms (lever R - u and R).
fn roll_table(rolls: &[RollRun]) -> Table {
    let header = [
        "case",
        "time to rolling (ms)",
        "closed form, lever R - u (ms)",
        "closed form, lever R (ms)",
        "rolling speed (m/s)",
        "closed form, R - u (m/s)",
        "centre height while sliding, as run (mm)",
        "R - u, u resting sag (mm)",
    ];
    Table {
        header: header.map(String::from).to_vec(),
        rows: rolls
            .iter()
            .map(|rr| {
                vec![
                    rr.label.clone(),
                    ms(rr.t_roll_s),
                    ms(rr.closed.time_s),
                    ms(rr.closed_plain.time_s),
                    fmt_sig(rr.rolling_speed_m_s),
                    fmt_sig(rr.closed.speed_m_s),
                    format!("{:.4}", rr.lever_m * 1e3),
                    format!("{:.4}", (rr.radius_m - rr.resting_overlap_m) * 1e3),
                ]
            })
            .collect(),
    }
}

/// The force chart of some impacts: each curve labelled with its peak force, drawn from the
/// run's own `forces.csv`.
fn force_chart(
    ctx: &mut Context,
    ex: &Executed,
    impacts: &[ImpactRun],
    file: &str,
    title: &str,
) -> Result<Chart, ValidateError> {
    let mut series = Vec::new();
    for (run, i) in ex.runs.iter().zip(impacts) {
        let curve = run.force_curve(i.contact)?;
        series.push(Series {
            label: format!("{} ({:.1} N)", i.label, i.peak_force_n),
            points: curve.points.iter().map(|&(t, p)| (t * 1e3, p)).collect(),
        });
    }
    let chart = LineChart::new(
        title,
        "time since first touch (ms)",
        "normal force P (N)",
        series,
    );
    write_chart(ctx, file, &chart)?;
    Ok(Chart {
        file: file.into(),
        caption: title.into(),
    })
}

/// A number to 4 decimals, `-` when there is none (a run that never rolled).
fn fmt_sig(x: f64) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    format!("{x:.4}")
}

/// A force in newtons to 2 decimals, `-` when there is none.
fn newton(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2}")
    } else {
        "-".into()
    }
}

/// A time in milliseconds to 3 decimals (a microsecond: the runs' 10 us step), `-` when none.
fn ms(x: f64) -> String {
    if x.is_finite() {
        format!("{:.3}", x * 1e3)
    } else {
        "-".into()
    }
}

/// Modulus in the paper's style: 1e4, 5e5, 1.1e6, 8.1e10.
fn modulus(x: f64) -> String {
    let e = x.abs().log10().floor() as i32;
    let m = x / 10f64.powi(e);
    let m = format!("{m:.2}");
    let m = m.trim_end_matches('0').trim_end_matches('.');
    format!("{m}e{e}")
}

/// A Fig. 4 platform by its shear modulus: `1e4 Pa`, `4e9 Pa (wood)`, `8.1e10 Pa (steel)`.
pub fn platform_name(g2_pa: f64) -> String {
    let what = if g2_pa == 4e9 {
        " (wood)"
    } else if g2_pa == 8.1e10 {
        " (steel)"
    } else {
        ""
    };
    format!("{} Pa{what}", modulus(g2_pa))
}

/// A ratio without trailing zeros: 0.01, 1, 4000, 81000.
fn fmt_g_ratio(x: f64) -> String {
    let s = format!("{x:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
