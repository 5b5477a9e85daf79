//! A run's CSV files as written and as read: how numbers are printed and whether the file is
//! gzipped ([`CsvFormat`], from the scenario's `output.precision` and `output.compress`), and the
//! one opener every reader of the project goes through ([`open`], [`locate`]), which reads
//! `NAME.csv` and `NAME.csv.gz` alike.
//!
//! With `output.compress` every CSV of a run is written as `NAME.csv.gz` (gzip, whole or not at
//! all as the plain files: [`super::atomic::AtomicCsv`]), and `summary.json`'s contact list as
//! [`super::CONTACTS_JSON_GZ`] ([`open`] reads it too); pandas (`read_csv` infers the
//! compression from `.gz`), R (`read.csv` opens gzipped files as they are) and the project's own
//! readers take either form.

use super::number::NumberFormat;
use crate::scenario::{OutputSpec, Precision};
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

/// The suffix a gzipped CSV carries after its `.csv`.
pub const GZ_SUFFIX: &str = ".gz";

/// How a run writes its CSV files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CsvFormat {
    /// How numbers are printed.
    pub numbers: NumberFormat,
    /// Gzip every CSV (`NAME.csv.gz`).
    pub compress: bool,
}

impl CsvFormat {
    /// The format a scenario's `output` asks for.
    pub fn of(spec: &OutputSpec) -> Self {
        Self {
            numbers: match spec.precision {
                Precision::Full => NumberFormat::FULL,
                Precision::Digits(n) => NumberFormat::digits(n),
            },
            compress: spec.compress,
        }
    }

    /// The file of CSV `name` (`bodies.csv`) in `dir` in this format: `dir/bodies.csv`, or
    /// `dir/bodies.csv.gz` when compressed.
    pub fn path(&self, dir: &Path, name: &str) -> PathBuf {
        dir.join(self.file_name(name))
    }

    /// The file name of CSV `name` in this format.
    pub fn file_name(&self, name: &str) -> String {
        if self.compress {
            format!("{name}{GZ_SUFFIX}")
        } else {
            name.to_string()
        }
    }
}

/// Whether `path` names a gzipped file (its name ends in `.gz`).
pub fn is_gzipped(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"))
}

/// `path` with `.gz` added to its name.
fn gz_of(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_os_string();
    s.push(GZ_SUFFIX);
    PathBuf::from(s)
}

/// The form of CSV `name` that a run folder holds: `dir/NAME` when that file exists, else
/// `dir/NAME.gz` when that one does, else `dir/NAME` (missing: a caller checking `is_file` or
/// opening it reports the plain name).
pub fn locate(dir: &Path, name: &str) -> PathBuf {
    resolve(&dir.join(name))
}

/// `path` if it exists, else its gzipped form if that exists, else `path`.
pub fn resolve(path: &Path) -> PathBuf {
    if path.exists() || is_gzipped(path) {
        return path.to_path_buf();
    }
    let gz = gz_of(path);
    if gz.is_file() {
        gz
    } else {
        path.to_path_buf()
    }
}

/// A CSV file open for reading, plain or gzipped.
pub enum Input {
    /// A plain file.
    Plain(BufReader<File>),
    /// A gzipped file, decompressed as it is read.
    Gz(flate2::read::GzDecoder<BufReader<File>>),
}

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Input::Plain(r) => r.read(buf),
            Input::Gz(r) => r.read(buf),
        }
    }
}

/// Opens the CSV file `path` for reading, plain or gzipped: a name ending in `.gz` is
/// decompressed; a plain name that does not exist is looked for with `.gz` added ([`resolve`]).
/// Returns the path opened (for messages) and the reader.
pub fn open(path: &Path) -> std::io::Result<(PathBuf, Input)> {
    let path = resolve(path);
    let file = BufReader::with_capacity(1 << 16, File::open(&path)?);
    let input = if is_gzipped(&path) {
        Input::Gz(flate2::read::GzDecoder::new(file))
    } else {
        Input::Plain(file)
    };
    Ok((path, input))
}

/// A CSV reader (headers on) of the file `path`, plain or gzipped ([`open`]), and the path
/// opened.
pub fn reader(path: &Path) -> std::io::Result<(PathBuf, csv::Reader<Input>)> {
    let (path, input) = open(path)?;
    Ok((path, csv::Reader::from_reader(input)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn opens_both_forms_by_the_plain_name() {
        let d = std::env::temp_dir().join(format!("applesim-csvfile-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("a.csv"), "x\n1\n").unwrap();
        let mut gz = flate2::write::GzEncoder::new(
            File::create(d.join("b.csv.gz")).unwrap(),
            flate2::Compression::default(),
        );
        gz.write_all(b"x\n2\n").unwrap();
        gz.finish().unwrap();
        for (name, want) in [("a.csv", "1"), ("b.csv", "2"), ("b.csv.gz", "2")] {
            let (path, mut rd) = reader(&d.join(name)).unwrap();
            let rows: Vec<String> = rd.records().map(|r| r.unwrap()[0].to_string()).collect();
            assert_eq!(rows, [want], "{}", path.display());
        }
        assert_eq!(locate(&d, "b.csv"), d.join("b.csv.gz"));
        assert_eq!(locate(&d, "c.csv"), d.join("c.csv"));
        let e = open(&d.join("c.csv")).err().unwrap();
        assert_eq!(e.kind(), std::io::ErrorKind::NotFound);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
