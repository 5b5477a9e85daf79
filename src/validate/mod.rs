//! Validation against the paper (`applesim validate`): its Figs. 1-7 as batch specs
//! (`scenarios/paper/figN.json`), run through the batch machinery, measured, compared with the
//! numbers the paper quotes, with closed forms and with our own accurate integration of the
//! impact (with gravity, where the closed forms of physics.md section 4 no longer hold), and
//! written up as a Markdown report with SVG charts beside it (`report.md`, `figN_*.svg`), with a
//! section on the paper's inconsistencies (physics.md section 9) and our evidence for each.
//!
//! Every check is a row with our value, the reference, the error, the tolerance and PASS/FAIL
//! ([`check::Check`]). The report holds no wall-clock time or path of the run folders, so the
//! same code gives the same report, byte for byte.
//!
//! Modules, in the order the data flows: `paper.json` ([`paper`]) holds the paper's words and
//! numbers and what each figure runs and checks; [`runs`] runs a spec and reads its run folders
//! back; [`measure`] measures each run and sets it beside its [`mod@reference`], the independent
//! reference values (self-contained: no formula of the product); [`figures`] builds every figure
//! from its spec with one builder; [`errata`] the evidence for the paper's errata; [`check`] one
//! row of a check table; [`report`] the Markdown.

pub mod check;
pub mod errata;
pub mod figures;
pub mod measure;
pub mod paper;
pub mod reference;
pub mod report;
pub mod runs;

use crate::chart::LineChart;
use crate::output::atomic;
use crate::output::plot::PlotError;
use check::Check;
use std::path::{Path, PathBuf};

/// Errors that stop the validation (a failing run does not: it is a failed check).
#[derive(Debug, thiserror::Error)]
pub enum ValidateError {
    /// A spec could not be loaded or its batch could not be run or merged.
    #[error(transparent)]
    Batch(#[from] crate::batch::BatchError),
    /// A run's file could not be read back or parsed.
    #[error("{path}: {message}")]
    Read {
        /// File or folder.
        path: PathBuf,
        /// What was wrong.
        message: String,
    },
    /// A run's curves could not be read back for a chart, or a chart drawn or written.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// A report file could not be written.
    #[error("writing {path}: {source}")]
    Io {
        /// File or folder.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// A scenario of a spec is not what the validation measures (e.g. no apple named as
    /// expected): the specs under `scenarios/paper/` were edited out of shape.
    #[error("{spec}: {message}")]
    Shape {
        /// The spec.
        spec: String,
        /// What the validation expected.
        message: String,
    },
}

/// Where the validation reads and writes. The report names the specs folder as given and
/// neither output folder, so it is the same bytes wherever it is written.
#[derive(Debug, Clone)]
pub struct Options {
    /// Folder of the figure specs (`fig1.json` ... `fig7.json`, `eq12_restitution.json`); the
    /// shipped ones are `scenarios/paper`. Shown in the report as given.
    pub specs_dir: PathBuf,
    /// Folder of the report and its charts.
    pub out_dir: PathBuf,
    /// Folder of the runs, one batch folder per figure (`RUNS/fig1/`, ...).
    pub runs_dir: PathBuf,
    /// Runs at a time within each figure's batch.
    pub jobs: usize,
}

/// A table of the report: header and rows of text cells, already formatted, so the Markdown
/// writer ([`report`]) knows nothing of units or precision.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    /// Column captions.
    pub header: Vec<String>,
    /// Rows.
    pub rows: Vec<Vec<String>>,
}

/// A chart of the report, written beside it (SVG, so the committed copy in docs/validation/
/// can be compared byte for byte).
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// File name in the output folder.
    pub file: String,
    /// What it shows (alt text and caption).
    pub caption: String,
}

/// One figure of the paper as the validation ran it: one section of the report, and what the
/// tests of the validation look into.
#[derive(Debug, Clone)]
pub struct Figure {
    /// `fig1`, ..., `fig7`.
    pub id: String,
    /// Heading.
    pub title: String,
    /// What the paper shows and claims for it.
    pub paper: String,
    /// The spec that ran it, as given.
    pub spec: String,
    /// The spec's description: the parameters and why.
    pub description: String,
    /// Charts.
    pub charts: Vec<Chart>,
    /// What every run gave.
    pub table: Table,
    /// Remarks under the table.
    pub notes: Vec<String>,
    /// The checks.
    pub checks: Vec<Check>,
    /// The impacts measured (Figs. 1-5), in run order.
    pub impacts: Vec<measure::ImpactRun>,
    /// The slip-to-roll runs (Figs. 6-7), in run order.
    pub rolls: Vec<measure::RollRun>,
}

/// What the validation found: every figure and erratum with its checks, and the files written.
#[derive(Debug, Clone)]
pub struct Validation {
    /// The figures, in order.
    pub figures: Vec<Figure>,
    /// The paper's inconsistencies with our evidence.
    pub errata: Vec<errata::Erratum>,
    /// The report file.
    pub report: PathBuf,
    /// Every file written into the output folder (report and charts).
    pub files: Vec<PathBuf>,
}

impl Validation {
    /// Every check, figure by figure, then those of the errata.
    pub fn checks(&self) -> impl Iterator<Item = &Check> {
        self.figures
            .iter()
            .flat_map(|f| f.checks.iter())
            .chain(self.errata.iter().flat_map(|e| e.checks.iter()))
    }

    /// The check with this key (`fig1/paper/peak_force/0.2`): keys are stable, so a test can hold
    /// one particular claim.
    pub fn check(&self, key: &str) -> Option<&Check> {
        self.checks().find(|c| c.key == key)
    }

    /// The figure with this id (`fig1`).
    pub fn figure(&self, id: &str) -> Option<&Figure> {
        self.figures.iter().find(|f| f.id == id)
    }

    /// Checks that failed: the command exits non-zero when there is any.
    pub fn failed(&self) -> Vec<&Check> {
        self.checks().filter(|c| !c.pass).collect()
    }
}

/// The product's materials handed to the reference (tests build them with
/// `Material::from_shear`, as the scenarios give them): the reference reads only their shear
/// modulus and Poisson ratio and derives E itself (physics.md section 1), so none of the
/// product's formulas enters a reference value.
impl From<&crate::contact::Material> for reference::Elastic {
    fn from(m: &crate::contact::Material) -> Self {
        reference::Elastic::from_shear(m.shear_modulus_pa, m.poisson_ratio)
    }
}

/// The report file name in the output folder (docs/validation/report.md for the committed copy).
pub const REPORT: &str = "report.md";

/// Runs every figure, writes the report and its charts into `opts.out_dir`, returns what was
/// found. `progress` gets one line per figure.
pub fn run(opts: &Options, progress: &mut dyn FnMut(&str)) -> Result<Validation, ValidateError> {
    std::fs::create_dir_all(&opts.out_dir).map_err(|source| ValidateError::Io {
        path: opts.out_dir.clone(),
        source,
    })?;
    let mut ctx = figures::Context {
        specs_dir: opts.specs_dir.clone(),
        out_dir: opts.out_dir.clone(),
        runs_dir: opts.runs_dir.clone(),
        jobs: opts.jobs.max(1),
        written: Vec::new(),
    };
    let mut figs = Vec::new();
    for spec in &paper::paper().figures {
        let f = figures::build(&mut ctx, spec)?;
        let id = &f.id;
        let pass = f.checks.iter().filter(|c| c.pass).count();
        progress(&format!(
            "{id}: {} runs, {pass} of {} checks pass",
            f.impacts.len() + f.rolls.len(),
            f.checks.len()
        ));
        figs.push(f);
    }
    let errata = errata::errata(&mut ctx, &figs)?;
    let pass = errata.iter().flat_map(|e| &e.checks).filter(|c| c.pass);
    progress(&format!(
        "errata: {} items, {} of {} checks pass",
        errata.len(),
        pass.count(),
        errata.iter().map(|e| e.checks.len()).sum::<usize>()
    ));
    let text = report::markdown(opts, &figs, &errata);
    let report = opts.out_dir.join(REPORT);
    write(&report, text.as_bytes())?;
    let mut files = ctx.written;
    files.push(report.clone());
    Ok(Validation {
        figures: figs,
        errata,
        report,
        files,
    })
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), ValidateError> {
    atomic::write_file(path, bytes).map_err(|source| ValidateError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Writes `chart` as `file` into the output folder and records it.
fn write_chart(
    ctx: &mut figures::Context,
    file: &str,
    chart: &LineChart,
) -> Result<(), ValidateError> {
    let path = ctx.out_dir.join(file);
    chart.write_svg(&path).map_err(PlotError::from)?;
    ctx.written.push(path);
    Ok(())
}
