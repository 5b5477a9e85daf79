//! `rollers.csv`: the free-turning rollers' spin at every output sample, one row per roller per
//! sample, at the same times as `bodies.csv` ([`ROLLERS_HEADER`]). A free roller's angle is
//! simulation state ([`crate::world::free_roller`]), not a function of time like a powered
//! roller's w t: without this file its turn between the start and the end (`summary.json`,
//! `free_rollers`) is lost, and the viewer could not draw it turning.
//!
//! Written only by a run of a scene that has a free-turning roller, so that every other run's
//! set of files stays what it was; streamed to a temporary file and renamed on
//! [`RollersCsv::commit`], as `bodies.csv` ([`super::atomic`]).

use super::atomic::AtomicCsv;
use super::BodiesCsv;
use crate::record::series::{AppleState, SampleSink};
use crate::world::free_roller::RollerSample;
use std::path::Path;

/// The file's name in a run folder.
pub const ROLLERS_CSV: &str = "rollers.csv";

/// Header of `rollers.csv`: the sample time, the roller's name (as in `contacts.csv`, a bed's
/// rollers `BED/k`), the angle it turned since the start (right-hand rule about its axis), its
/// rate over the step that ended at the sample, and its surface speed (rate times radius).
pub const ROLLERS_HEADER: [&str; 5] = [
    "time_s",
    "roller",
    "angle_rad",
    "spin_rad_s",
    "surface_speed_m_s",
];

/// Streams `rollers.csv` to a temporary file, renamed on [`RollersCsv::commit`].
pub struct RollersCsv {
    w: AtomicCsv,
    nf: super::NumberFormat,
}

impl RollersCsv {
    /// Starts `path` (gzipped when its name ends in `.gz`), numbers as `nf` prints them.
    pub fn create(path: &Path, nf: super::NumberFormat) -> std::io::Result<Self> {
        let w = AtomicCsv::create(path, &ROLLERS_HEADER)?;
        Ok(Self { w, nf })
    }

    /// Finishes the file under its final name.
    pub fn commit(self) -> std::io::Result<()> {
        self.w.commit()
    }

    /// The rows of one sample (numbers as every CSV output prints them, [`super::number`]).
    fn write(&mut self, time_s: f64, rollers: &[RollerSample]) -> std::io::Result<()> {
        let nf = self.nf;
        let t = nf.num(time_s);
        for r in rollers {
            self.w.write_record([
                t.as_str(),
                &r.name,
                &nf.num(r.angle_rad),
                &nf.num(r.spin_rad_s),
                &nf.num(r.surface_speed_m_s),
            ])?;
        }
        Ok(())
    }
}

/// The run's sample sink: the apples into `bodies.csv`, the free-turning rollers (when the scene
/// has some) into `rollers.csv`, one sample feeding both.
pub struct RunSamples<'a> {
    /// `bodies.csv`.
    pub bodies: &'a mut BodiesCsv,
    /// `rollers.csv`, if the scene has a free-turning roller.
    pub rollers: Option<&'a mut RollersCsv>,
    /// The file whose write failed, if one did (`bodies.csv` or `rollers.csv`): the run's error
    /// names it, and so the folder (a disk full or a file size limit, EFBIG, mid-run).
    pub failed: Option<&'static str>,
}

impl SampleSink for RunSamples<'_> {
    fn sample(&mut self, time_s: f64, apples: &[AppleState]) -> std::io::Result<()> {
        self.bodies
            .sample(time_s, apples)
            .inspect_err(|_| self.failed = Some("bodies.csv"))
    }

    fn sample_rollers(&mut self, time_s: f64, rollers: &[RollerSample]) -> std::io::Result<()> {
        match self.rollers.as_mut() {
            Some(r) => r
                .write(time_s, rollers)
                .inspect_err(|_| self.failed = Some(ROLLERS_CSV)),
            None => Ok(()),
        }
    }
}
