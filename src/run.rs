//! A run from scenario to result folder: simulate ([`crate::sim`]), analyse
//! ([`crate::analysis`]), write every file ([`crate::output`]), and switch the folder in whole.
//!
//! This is the order of a run's stages in one place, as rapier's `PhysicsPipeline::step` holds the
//! order of its stages: the CLI (`applesim run`) and a batch's runs call [`to_dir`] or
//! [`into_dir`]; the stages themselves know nothing of each other's files.

use crate::output::{self, atomic};
use crate::scenario::Scenario;
use crate::sim::RunResult;
use std::path::Path;

/// Whether `name`, an entry of a result folder, is something an applesim run writes: its
/// JSON, CSV (plain or gzipped), SVG and ParaView files, `audit.md`, the `vtk/` folder, the
/// viewer's page (`view.html`, from `applesim run --view` or `applesim view`), and the hidden
/// temporaries of earlier versions' killed writers (a user's own notes, say `notes.md`, are
/// not). A folder holding anything else is not replaced ([`atomic::StagedFolder::begin`]).
pub fn is_run_file(name: &str, is_dir: bool) -> bool {
    if is_dir {
        return name == output::vtk::VTK_DIR;
    }
    if name == output::audit::AUDIT_MD {
        return true;
    }
    if name.starts_with('.') && name.contains(".tmp-") {
        return true;
    }
    let ext = Path::new(name)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    matches!(
        ext.as_deref(),
        Some("json" | "csv" | "gz" | "svg" | "pvd" | "vtp" | "vtu" | "html")
    )
}

/// Errors of [`to_dir`].
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The run itself failed (and wrote nothing).
    #[error(transparent)]
    Sim(#[from] crate::sim::SimError),
    /// An output file could not be written.
    #[error("writing {path}: {source}")]
    Io {
        /// The file or folder.
        path: std::path::PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// The ParaView files could not be written (or `bodies.csv` could not be read back for them).
    #[error("ParaView output: {0}")]
    Vtk(#[from] output::vtk::VtkError),
    /// The result folder could not be locked, staged or switched in (another run is writing
    /// it, it is not a result folder, or the file system refused).
    #[error(transparent)]
    Folder(#[from] atomic::FolderError),
    /// The charts written into the set (`applesim run --plots`) failed.
    #[error("charts: {0}")]
    Plot(#[from] output::plot::PlotError),
}

fn io_at(path: &Path) -> impl FnOnce(std::io::Error) -> RunError + '_ {
    move |source| RunError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Runs a validated scenario and writes its whole set of files into `out_dir` (see
/// [`into_dir`] for the files), switching the set in at once: `out_dir` holds either the
/// previous run's complete set or this one's, never a mix, whatever stops the run (an error,
/// a full disk, kill -9). The folder is locked while the run runs (a second run into it is
/// refused with [`atomic::FolderError::Busy`]); a folder that is not a run's set is refused,
/// never replaced ([`atomic::FolderError::NotARunFolder`]); nothing temporary is left beside it.
pub fn to_dir(
    sc: &Scenario,
    base_dir: &Path,
    out_dir: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<RunResult, RunError> {
    to_dir_with(sc, base_dir, out_dir, progress, &mut |_, _| Ok(()))
}

/// [`to_dir`], with `also` writing more files into the set before it is switched in (its
/// first argument is the folder being written, under a temporary name; the charts of
/// `applesim run --plots` go in this way, so they belong to the set).
pub fn to_dir_with(
    sc: &Scenario,
    base_dir: &Path,
    out_dir: &Path,
    progress: &mut dyn FnMut(f64),
    also: &mut dyn FnMut(&Path, &RunResult) -> Result<(), RunError>,
) -> Result<RunResult, RunError> {
    let lock = atomic::FolderLock::acquire(out_dir)?;
    let stage = atomic::StagedFolder::begin(&lock, is_run_file)?;
    let named = |e: RunError| match e {
        // Name the file as the user knows it, not by its temporary folder.
        RunError::Io { path, source } => RunError::Io {
            path: stage.final_path(&path),
            source,
        },
        other => other,
    };
    let result = into_dir(sc, base_dir, stage.path(), progress).map_err(named)?;
    also(stage.path(), &result).map_err(named)?;
    stage.commit()?;
    Ok(result)
}

/// Runs a validated scenario and writes into the folder `out_dir` (created if missing; use
/// [`to_dir`] for a result folder the user sees, this one writes in place):
/// `summary.json`, `contacts.csv`, `bodies.csv`, `scenario.json`, `apple_contacts.csv`,
/// (every CSV as `NAME.csv.gz` with `output.compress`, numbers as `output.precision` asks,
/// [`output::csv_file`])
/// `bruises.csv`, `audit.csv`, `audit.md`, `ird.svg` (with impacts), the probes' files; in a scene with
/// a free-turning roller `rollers.csv` ([`output::rollers`]); with force
/// histories (`output.force_history`) `forces.csv` and `pulse_fits.csv`; with `output.vtk` the
/// ParaView files ([`output::vtk`]). The analysis ([`crate::analysis::analyse`]) adds its headline
/// figures to the returned `metrics`. `summary.json` comes last.
pub fn into_dir(
    sc: &Scenario,
    base_dir: &Path,
    out_dir: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<RunResult, RunError> {
    std::fs::create_dir_all(out_dir).map_err(io_at(out_dir))?;
    let csv = output::CsvFormat::of(&sc.output);
    let nf = csv.numbers;
    let sim = crate::sim::Simulation::new(sc, base_dir)?;
    let surfaces = sc
        .output
        .vtk
        .as_ref()
        .map(|_| output::vtk::SceneSurfaces::capture(sim.world()));
    let bodies_path = csv.path(out_dir, "bodies.csv");
    let mut bodies = output::BodiesCsv::create(&bodies_path, nf, sim.world().has_spheroids())
        .map_err(io_at(&bodies_path))?;
    let rollers_path = csv.path(out_dir, output::ROLLERS_CSV);
    let mut rollers = match sim.world().has_free_rollers() {
        true => Some(output::RollersCsv::create(&rollers_path, nf).map_err(io_at(&rollers_path))?),
        false => None,
    };
    let mut sink = output::rollers::RunSamples {
        bodies: &mut bodies,
        rollers: rollers.as_mut(),
        failed: None,
    };
    let mut result = match sim.run(&mut sink, progress) {
        Ok(r) => r,
        // A sample that could not be written names its file (and so the folder).
        Err(crate::sim::SimError::Io(source)) => {
            let path = out_dir.join(sink.failed.unwrap_or("bodies.csv"));
            return Err(RunError::Io { path, source });
        }
        Err(e) => return Err(e.into()),
    };
    bodies.commit().map_err(io_at(&bodies_path))?;
    if let Some(r) = rollers {
        r.commit().map_err(io_at(&rollers_path))?;
    }
    let analysis = crate::analysis::analyse(sc, &result);
    analysis.add_metrics(&mut result.metrics);
    result
        .warnings
        .extend(analysis.bruise.warnings.iter().cloned());
    if let (Some(v), Some(surfaces)) = (&sc.output.vtk, &surfaces) {
        let order: Vec<&str> = result.apples.iter().map(|a| a.name.as_str()).collect();
        let written = output::vtk::write_vtk(
            out_dir,
            sc,
            surfaces,
            &analysis.bruise,
            &order,
            v.interval_s,
        )?;
        result.warnings.extend(written.warnings);
        result
            .metrics
            .insert("vtk_frames".into(), written.frames.len() as f64);
    }
    if sc.force_history().is_kept() {
        let p = csv.path(out_dir, "forces.csv");
        output::write_forces(&p, &result.events, nf).map_err(io_at(&p))?;
        let p = csv.path(out_dir, "pulse_fits.csv");
        output::write_pulse_fits(&p, &analysis.pulse_fits, nf).map_err(io_at(&p))?;
    }
    let p = csv.path(out_dir, output::APPLE_CONTACTS_CSV);
    output::write_apple_contacts(&p, &analysis, nf).map_err(io_at(&p))?;
    let p = csv.path(out_dir, output::BRUISES_CSV);
    output::write_bruises(&p, &analysis, nf).map_err(io_at(&p))?;
    let p = csv.path(out_dir, "audit.csv");
    output::audit::write_audit(&p, &analysis.audit, nf).map_err(io_at(&p))?;
    let p = out_dir.join(output::audit::AUDIT_MD);
    let title = sc.description.as_deref().unwrap_or("run");
    atomic::write_file(&p, analysis.audit.markdown(title).as_bytes()).map_err(io_at(&p))?;
    let points = &analysis.contact_points;
    for pr in &result.probes {
        output::probe::write_probe(out_dir, pr, &result.events, points, &csv)
            .map_err(|(path, source)| RunError::Io { path, source })?;
    }
    if let Some(chart) =
        crate::analysis::audit::ird_chart(points, &analysis.bruise, &result.roster, title)
    {
        chart
            .write_svg(&out_dir.join("ird.svg"))
            .map_err(output::plot::PlotError::from)?;
    }
    let p = csv.path(out_dir, "contacts.csv");
    output::write_contacts(&p, &result.events, points, &result.roster, nf).map_err(io_at(&p))?;
    if result.transition_summary.is_some() {
        let p = csv.path(out_dir, "transitions.csv");
        output::write_transitions(&p, &result.transitions, nf).map_err(io_at(&p))?;
    }
    let p = out_dir.join("scenario.json");
    output::write_scenario(&p, sc).map_err(io_at(&p))?;
    let p = out_dir.join("summary.json");
    output::write_summary_with(&p, sc, &result, Some(&analysis)).map_err(io_at(&p))?;
    Ok(result)
}
