//! Outputs are written whole or not at all.
//!
//! - A file ([`AtomicFile`]) is written to a hidden temporary name in its folder, flushed and
//!   synced, then renamed (atomic on POSIX file systems).
//! - A result folder ([`StagedFolder`]) is written as a whole set into a temporary folder beside
//!   it and switched in at once: on Linux `renameat2(RENAME_EXCHANGE)` swaps the two folders
//!   atomically, so the folder's path names the previous complete set until the instant it
//!   names the new one; elsewhere (or on a file system without the exchange) two renames do it,
//!   and a writer killed between them leaves the old set beside the path, put back by the next
//!   writer. A kill -9, a full disk or an error at any point therefore leaves either the old
//!   set or the new one, never a mix of their files.
//! - Writers of one folder exclude each other by a [`FolderLock`] (`flock` on `.NAME.lock`
//!   beside the folder): a lock the kernel drops when its holder dies, however it dies, which
//!   is what makes the temporaries of a dead writer safe to remove and a live writer's never.
//!   `flock` works between nodes over NFS v4 (Linux maps it to NFS byte-range locks).

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// A file being written; it appears under its final name only on [`AtomicFile::commit`].
/// Dropped without a successful commit (including a commit that failed), the temporary file is
/// removed.
pub struct AtomicFile {
    tmp: PathBuf,
    dest: PathBuf,
    writer: Option<BufWriter<File>>,
    renamed: bool,
}

impl AtomicFile {
    /// Starts writing `dest` (its folder must exist).
    pub fn create(dest: &Path) -> std::io::Result<Self> {
        let name = dest
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_else(|| "out".into());
        let tmp = dest.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
        let file = File::create(&tmp)?;
        Ok(Self {
            tmp,
            dest: dest.to_path_buf(),
            writer: Some(BufWriter::with_capacity(1 << 16, file)),
            renamed: false,
        })
    }

    /// Flushes, syncs and renames to the final name. On error the temporary file is removed
    /// (by the drop that follows).
    pub fn commit(mut self) -> std::io::Result<()> {
        let w = self.writer.take().expect("writer present until commit");
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&self.tmp, &self.dest)?;
        self.renamed = true;
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer.as_mut().expect("not committed").write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.writer.as_mut().expect("not committed").flush()
    }
}

/// A CSV file written whole or not at all: a [`csv::Writer`] (reached through `Deref`, so rows
/// are `write_record`s) over an [`AtomicFile`], its header written first, and the file under its
/// final name only on [`AtomicCsv::commit`]. A name ending in `.gz` (`bodies.csv.gz`,
/// `output.compress`) is written gzipped, and is as whole: the gzip stream is finished before the
/// file is renamed. Every CSV output is one, so each writes its rows and nothing of the
/// temporary-file protocol.
pub struct AtomicCsv {
    w: csv::Writer<CsvSink>,
}

/// What an [`AtomicCsv`] writes into: the file itself, or a gzip stream into it.
pub enum CsvSink {
    /// Plain text.
    Plain(AtomicFile),
    /// Gzipped (level 6, zlib's default; a fixed header without a time stamp, so the same rows
    /// give the same bytes).
    Gz(flate2::write::GzEncoder<AtomicFile>),
}

impl CsvSink {
    fn commit(self) -> std::io::Result<()> {
        match self {
            CsvSink::Plain(f) => f.commit(),
            CsvSink::Gz(g) => g.finish()?.commit(),
        }
    }
}

impl Write for CsvSink {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self {
            CsvSink::Plain(f) => f.write(buf),
            CsvSink::Gz(g) => g.write(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match self {
            CsvSink::Plain(f) => f.flush(),
            CsvSink::Gz(g) => g.flush(),
        }
    }
}

impl AtomicCsv {
    /// Starts writing `dest` (its folder must exist) with the row `header`; gzipped when its
    /// name ends in `.gz`.
    pub fn create(dest: &Path, header: &[&str]) -> std::io::Result<Self> {
        let file = AtomicFile::create(dest)?;
        let sink = if super::csv_file::is_gzipped(dest) {
            CsvSink::Gz(flate2::write::GzEncoder::new(
                file,
                flate2::Compression::new(GZIP_LEVEL),
            ))
        } else {
            CsvSink::Plain(file)
        };
        let mut w = csv::WriterBuilder::new()
            .buffer_capacity(1 << 16)
            .from_writer(sink);
        w.write_record(header)?;
        Ok(Self { w })
    }

    /// Flushes the rows, finishes the gzip stream if any, and renames the file to its final
    /// name ([`AtomicFile::commit`]).
    pub fn commit(self) -> std::io::Result<()> {
        self.w.into_inner().map_err(|e| e.into_error())?.commit()
    }
}

/// The gzip level of compressed CSV files (zlib's default).
pub const GZIP_LEVEL: u32 = 6;

impl std::ops::Deref for AtomicCsv {
    type Target = csv::Writer<CsvSink>;
    fn deref(&self) -> &Self::Target {
        &self.w
    }
}

impl std::ops::DerefMut for AtomicCsv {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.w
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if !self.renamed {
            // Close first (a buffered writer's failed flush is of no interest: the file goes).
            drop(self.writer.take());
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Writes a whole file atomically.
pub fn write_file(dest: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut f = AtomicFile::create(dest)?;
    f.write_all(bytes)?;
    f.commit()
}

/// Why a result folder could not be locked, staged or switched in.
#[derive(Debug, thiserror::Error)]
pub enum FolderError {
    /// Another process holds the folder's lock: it is writing the folder now.
    #[error(
        "{path}: another applesim process is writing this folder now (it holds {}); \
         wait for it to finish, or choose another folder",
        lock.display()
    )]
    Busy {
        /// The result folder.
        path: PathBuf,
        /// Its lock file.
        lock: PathBuf,
    },
    /// The path holds something that is not an applesim result folder: it is left alone.
    #[error(
        "{path}: {reason}; applesim replaces a folder only when it holds a previous run's \
         files, so it leaves this one alone: remove it or choose another folder"
    )]
    NotARunFolder {
        /// The path.
        path: PathBuf,
        /// What is there.
        reason: String,
    },
    /// A file system operation failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> FolderError + '_ {
    move |source| FolderError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// `dest` made absolute with symbolic links resolved (the set must be staged beside the real
/// folder, on its file system), its parent folders created; and its final name.
fn resolve(dest: &Path) -> Result<(PathBuf, String), FolderError> {
    let real = if std::fs::symlink_metadata(dest).is_ok() {
        std::fs::canonicalize(dest).map_err(io_err(dest))?
    } else {
        let name = dest.file_name().ok_or_else(|| FolderError::NotARunFolder {
            path: dest.to_path_buf(),
            reason: "this path does not end in a folder name".into(),
        })?;
        let parent = match dest.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(io_err(&parent))?;
        std::fs::canonicalize(&parent)
            .map_err(io_err(&parent))?
            .join(name)
    };
    let name = real
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .ok_or_else(|| FolderError::NotARunFolder {
            path: dest.to_path_buf(),
            reason: "the root folder cannot be a result folder".into(),
        })?;
    Ok((real, name))
}

/// The exclusive right to write one result folder: an `flock` on `.NAME.lock` beside it.
/// Released (and the lock file removed) on drop; released by the kernel if the holder dies.
pub struct FolderLock {
    file: File,
    lock_path: PathBuf,
    dest: PathBuf,
    name: String,
    /// False for a lock inherited from a parent process: the parent removes the lock file.
    owned: bool,
}

impl std::fmt::Debug for FolderLock {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FolderLock")
            .field("lock_path", &self.lock_path)
            .field("owned", &self.owned)
            .finish()
    }
}

/// Whether `path` still names the open `file` (same device and inode).
fn names(path: &Path, file: &File) -> std::io::Result<bool> {
    let on_disk = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
        Err(e) => return Err(e),
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let open = file.metadata()?;
        Ok(open.dev() == on_disk.dev() && open.ino() == on_disk.ino())
    }
    #[cfg(not(unix))]
    {
        let _ = (file, on_disk);
        Ok(true)
    }
}

/// Takes an exclusive `flock` on `file` without waiting; false if another open file holds it.
#[cfg(unix)]
fn try_lock(file: &File) -> std::io::Result<bool> {
    use std::os::fd::AsRawFd;
    loop {
        // SAFETY: flock on a descriptor this File owns.
        if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } == 0 {
            return Ok(true);
        }
        let e = std::io::Error::last_os_error();
        match e.raw_os_error() {
            Some(libc::EWOULDBLOCK) => return Ok(false),
            Some(libc::EINTR) => continue,
            _ => return Err(e),
        }
    }
}

/// Elsewhere folders are not locked (applesim's locks are Unix `flock`s).
#[cfg(not(unix))]
fn try_lock(_file: &File) -> std::io::Result<bool> {
    Ok(true)
}

impl FolderLock {
    /// The lock file of result folder `dest`: `.NAME.lock` beside it.
    pub fn lock_path(dest: &Path) -> PathBuf {
        let name = dest
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        dest.with_file_name(format!(".{name}.lock"))
    }

    /// Takes the lock of `dest` without waiting; `None` when another process (or another lock
    /// in this one) holds it. Creates `dest`'s parent folders.
    pub fn try_acquire(dest: &Path) -> Result<Option<FolderLock>, FolderError> {
        let (dest, name) = resolve(dest)?;
        let lock_path = FolderLock::lock_path(&dest);
        loop {
            let file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&lock_path)
                .map_err(io_err(&lock_path))?;
            match try_lock(&file) {
                Ok(true) => {}
                Ok(false) => return Ok(None),
                Err(e) => {
                    return Err(FolderError::Io {
                        path: lock_path,
                        source: e,
                    })
                }
            }
            // The holder we waited for may have removed the file between our open and our
            // lock (it does so as it lets go): then the lock is on a file nobody else will
            // open, and the path must be tried again.
            if names(&lock_path, &file).map_err(io_err(&lock_path))? {
                return Ok(Some(FolderLock {
                    file,
                    lock_path,
                    dest,
                    name,
                    owned: true,
                }));
            }
        }
    }

    /// Takes the lock of `dest`, or says who has it ([`FolderError::Busy`]).
    pub fn acquire(dest: &Path) -> Result<FolderLock, FolderError> {
        FolderLock::try_acquire(dest)?.ok_or_else(|| FolderError::Busy {
            path: dest.to_path_buf(),
            lock: FolderLock::lock_path(dest),
        })
    }

    /// The folder this lock guards (absolute, links resolved).
    pub fn dest(&self) -> &Path {
        &self.dest
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.lock_path
    }

    /// The file descriptor holding the lock, for a child process to inherit (an `flock` belongs
    /// to the open file, shared by every descriptor of it: the lock then lasts until both
    /// processes have let go, so a writer's temporaries are never taken for a dead writer's
    /// while either is alive).
    #[cfg(unix)]
    pub fn raw_fd(&self) -> i32 {
        use std::os::fd::AsRawFd;
        self.file.as_raw_fd()
    }

    /// The lock of `dest` held by descriptor `fd`, inherited from the parent process that took
    /// it. Checks that `fd` is open on `dest`'s lock file. The parent keeps the duty of removing
    /// the lock file: dropping this one only closes the descriptor.
    ///
    /// # Safety
    /// `fd` must be an open descriptor that nothing else in this process owns or closes.
    #[cfg(unix)]
    pub unsafe fn inherited(fd: i32, dest: &Path) -> Result<FolderLock, FolderError> {
        use std::os::fd::FromRawFd;
        let (dest, name) = resolve(dest)?;
        let lock_path = FolderLock::lock_path(&dest);
        // SAFETY: the caller guarantees that `fd` is open and owned by nobody else.
        let file = unsafe { File::from_raw_fd(fd) };
        if !names(&lock_path, &file).map_err(io_err(&lock_path))? {
            // Not ours to close: leak it rather than close a descriptor we were wrong about.
            std::mem::forget(file);
            return Err(FolderError::Io {
                path: lock_path,
                source: std::io::Error::other(format!(
                    "descriptor {fd} handed down by the parent process is not this lock file"
                )),
            });
        }
        Ok(FolderLock {
            file,
            lock_path,
            dest,
            name,
            owned: false,
        })
    }

    /// Whether `entry` (a name in the folder's parent) is a temporary of this folder's
    /// writers: a staged set (`.NAME.tmp-*`), a set moved aside (`.NAME.old-*`), a batch job
    /// file (`.NAME.job-*`) or a failure record being written (`.NAME.failed.json.tmp-*`).
    fn is_temporary(&self, entry: &str) -> bool {
        let Some(rest) = entry
            .strip_prefix('.')
            .and_then(|r| r.strip_prefix(self.name.as_str()))
            .and_then(|r| r.strip_prefix('.'))
        else {
            return false;
        };
        ["tmp-", "old-", "job-", "failed.json.tmp-"]
            .iter()
            .any(|p| rest.starts_with(p))
    }

    /// Removes what killed writers of this folder left beside it (only the holder of the lock
    /// may: nobody else is writing them), and puts back a complete set that a writer killed
    /// between the two renames of the fallback switch had moved aside. Returns how many
    /// entries were removed.
    pub fn remove_stale(&self) -> Result<usize, FolderError> {
        let parent = self.dest.parent().unwrap_or(Path::new("/"));
        let mut entries: Vec<(String, PathBuf)> = std::fs::read_dir(parent)
            .map_err(io_err(parent))?
            .filter_map(|e| e.ok())
            .map(|e| (e.file_name().to_string_lossy().to_string(), e.path()))
            .filter(|(n, _)| self.is_temporary(n))
            .collect();
        entries.sort();
        let mut removed = 0;
        for (name, p) in entries {
            let aside = name[self.name.len() + 2..].starts_with("old-");
            if aside
                && std::fs::symlink_metadata(&self.dest).is_err()
                && p.join("summary.json").is_file()
            {
                std::fs::rename(&p, &self.dest).map_err(io_err(&p))?;
                continue;
            }
            remove_any(&p).map_err(io_err(&p))?;
            removed += 1;
        }
        Ok(removed)
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Remove the file while still holding the lock, then close (which unlocks): a process
        // that opened the old file meanwhile sees, once it gets the lock, that the path no
        // longer names it and tries again.
        if self.owned {
            let _ = std::fs::remove_file(&self.lock_path);
        }
    }
}

fn remove_any(p: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(p) {
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(p),
        Ok(_) => std::fs::remove_file(p),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// Tells whether an entry of a result folder (its name, and whether it is a folder) is something
/// a run writes: the caller's rule (`crate::run::is_run_file` for a run folder), so that this
/// writer knows no output's name.
pub type RunFileRule = fn(&str, bool) -> bool;

/// Refuses to replace anything but a missing folder, an empty one or a previous run's set.
fn check_replaceable(dest: &Path, is_run_file: RunFileRule) -> Result<(), FolderError> {
    let not = |reason: String| FolderError::NotARunFolder {
        path: dest.to_path_buf(),
        reason,
    };
    let meta = match std::fs::symlink_metadata(dest) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(io_err(dest)(e)),
    };
    if !meta.is_dir() {
        return Err(not("this is a file, not a folder".into()));
    }
    let mut names: Vec<(String, bool)> = std::fs::read_dir(dest)
        .map_err(io_err(dest))?
        .filter_map(|e| e.ok())
        .map(|e| {
            let dir = e.file_type().map(|t| t.is_dir()).unwrap_or(false);
            (e.file_name().to_string_lossy().to_string(), dir)
        })
        .collect();
    if names.is_empty() {
        return Ok(());
    }
    names.sort();
    if !names.iter().any(|(n, d)| n == "summary.json" && !d) {
        return Err(not(format!(
            "this folder is not empty (it holds '{}'{}) and no summary.json, so it \
             is not an applesim result folder",
            names[0].0,
            match names.len() {
                1 => String::new(),
                n => format!(" and {} more", n - 1),
            }
        )));
    }
    if let Some((n, _)) = names.iter().find(|(n, d)| !is_run_file(n, *d)) {
        return Err(not(format!(
            "this result folder also holds '{n}', which applesim does not write (the whole \
             folder would be replaced)"
        )));
    }
    Ok(())
}

/// Fsyncs every file and folder under `dir` (the set must be on disk before it is switched in).
fn sync_tree(dir: &Path) -> std::io::Result<()> {
    for e in std::fs::read_dir(dir)? {
        let e = e?;
        if e.file_type()?.is_dir() {
            sync_tree(&e.path())?;
        } else {
            File::open(e.path())?.sync_all()?;
        }
    }
    sync_dir(dir)
}

fn sync_dir(dir: &Path) -> std::io::Result<()> {
    #[cfg(unix)]
    {
        File::open(dir)?.sync_all()
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        Ok(())
    }
}

/// Swaps two paths atomically. `Ok(false)` where the system or file system cannot.
#[cfg(any(target_os = "linux", target_os = "android"))]
fn exchange(a: &Path, b: &Path) -> std::io::Result<bool> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let ca = CString::new(a.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
    let cb = CString::new(b.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
    // SAFETY: two valid NUL-terminated paths; renameat2 reads them and nothing else.
    let r = unsafe {
        libc::syscall(
            libc::SYS_renameat2,
            libc::AT_FDCWD,
            ca.as_ptr(),
            libc::AT_FDCWD,
            cb.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if r == 0 {
        return Ok(true);
    }
    let e = std::io::Error::last_os_error();
    match e.raw_os_error() {
        Some(libc::EINVAL | libc::ENOSYS | libc::EOPNOTSUPP) => Ok(false),
        _ => Err(e),
    }
}

#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn exchange(_a: &Path, _b: &Path) -> std::io::Result<bool> {
    Ok(false)
}

static STAGE_SEQ: AtomicU64 = AtomicU64::new(0);

/// A result folder's new set being written into `.NAME.tmp-<pid>-<n>` beside it, under its
/// [`FolderLock`]. [`StagedFolder::commit`] switches it in whole; dropped without a commit, the
/// temporary folder is removed.
pub struct StagedFolder<'a> {
    lock: &'a FolderLock,
    is_run_file: RunFileRule,
    tmp: PathBuf,
    committed: bool,
}

impl<'a> StagedFolder<'a> {
    /// Checks that the locked folder may be replaced (missing, empty or a previous run's set),
    /// removes what killed writers left beside it, and creates the empty temporary folder.
    /// `is_run_file` tells what a run writes: a folder holding anything else is not replaced.
    pub fn begin(
        lock: &'a FolderLock,
        is_run_file: RunFileRule,
    ) -> Result<StagedFolder<'a>, FolderError> {
        lock.remove_stale()?;
        check_replaceable(&lock.dest, is_run_file)?;
        let tmp = lock.dest.with_file_name(format!(
            ".{}.tmp-{}-{}",
            lock.name,
            std::process::id(),
            STAGE_SEQ.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir(&tmp).map_err(io_err(&tmp))?;
        Ok(StagedFolder {
            lock,
            is_run_file,
            tmp,
            committed: false,
        })
    }

    /// The temporary folder to write the set into.
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// The result folder it will become.
    pub fn dest(&self) -> &Path {
        &self.lock.dest
    }

    /// `path` inside the temporary folder as it will be named once switched in (for messages).
    pub fn final_path(&self, path: &Path) -> PathBuf {
        match path.strip_prefix(&self.tmp) {
            Ok(rel) if rel.as_os_str().is_empty() => self.lock.dest.clone(),
            Ok(rel) => self.lock.dest.join(rel),
            Err(_) => path.to_path_buf(),
        }
    }

    /// Syncs the set and switches it in whole; then removes the previous set.
    pub fn commit(mut self) -> Result<(), FolderError> {
        let dest = self.lock.dest.clone();
        sync_tree(&self.tmp).map_err(io_err(&self.tmp))?;
        check_replaceable(&dest, self.is_run_file)?;
        let parent = dest.parent().unwrap_or(Path::new("/")).to_path_buf();
        let had_old = std::fs::symlink_metadata(&dest).is_ok();
        // After the switch the old set sits at `old` (the temporary name after an exchange).
        let old = if !had_old {
            std::fs::rename(&self.tmp, &dest).map_err(io_err(&dest))?;
            None
        } else if exchange(&self.tmp, &dest).map_err(io_err(&dest))? {
            Some(self.tmp.clone())
        } else {
            let aside = dest.with_file_name(format!(
                ".{}.old-{}-{}",
                self.lock.name,
                std::process::id(),
                STAGE_SEQ.fetch_add(1, Ordering::Relaxed)
            ));
            std::fs::rename(&dest, &aside).map_err(io_err(&dest))?;
            if let Err(e) = std::fs::rename(&self.tmp, &dest) {
                let _ = std::fs::rename(&aside, &dest);
                return Err(io_err(&dest)(e));
            }
            Some(aside)
        };
        self.committed = true;
        sync_dir(&parent).map_err(io_err(&parent))?;
        if let Some(old) = old {
            // The switch is done; an old set that cannot be removed now is removed as a stale
            // temporary by the next writer.
            let _ = std::fs::remove_dir_all(old);
        }
        Ok(())
    }
}

impl Drop for StagedFolder<'_> {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.tmp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("applesim-atomic-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        v.sort();
        v
    }

    /// The rule of these tests: a run writes CSV and JSON files only.
    fn csv_or_json(name: &str, is_dir: bool) -> bool {
        !is_dir && (name.ends_with(".csv") || name.ends_with(".json"))
    }

    fn write_set(stage: &StagedFolder, tag: &str) {
        for f in ["bodies.csv", "summary.json"] {
            std::fs::write(stage.path().join(f), format!("{tag} {f}")).unwrap();
        }
    }

    #[test]
    fn a_failed_commit_leaves_no_temporary_file() {
        let d = scratch("file");
        let dest = d.join("missing-folder").join("x.csv");
        // The temporary cannot even be created: nothing to leak.
        assert!(AtomicFile::create(&dest).is_err());
        // A rename onto a non-empty folder fails after the temporary was written.
        let dest = d.join("occupied");
        std::fs::create_dir_all(dest.join("inside")).unwrap();
        let mut f = AtomicFile::create(&dest).unwrap();
        f.write_all(b"abc").unwrap();
        assert!(f.commit().is_err());
        assert_eq!(listing(&d), ["occupied"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_set_is_switched_in_whole_and_nothing_is_left_beside_it() {
        let d = scratch("switch");
        let dest = d.join("run");
        for tag in ["first", "second"] {
            let lock = FolderLock::acquire(&dest).unwrap();
            let stage = StagedFolder::begin(&lock, csv_or_json).unwrap();
            write_set(&stage, tag);
            assert_eq!(
                stage.final_path(&stage.path().join("bodies.csv")),
                d.canonicalize().unwrap().join("run/bodies.csv")
            );
            stage.commit().unwrap();
            drop(lock);
            assert_eq!(
                std::fs::read_to_string(dest.join("bodies.csv")).unwrap(),
                format!("{tag} bodies.csv")
            );
            assert_eq!(listing(&d), ["run"]);
        }
        // Dropped before commit: the old set stays, the temporary goes.
        let lock = FolderLock::acquire(&dest).unwrap();
        let stage = StagedFolder::begin(&lock, csv_or_json).unwrap();
        write_set(&stage, "third");
        drop(stage);
        drop(lock);
        assert_eq!(listing(&d), ["run"]);
        assert_eq!(
            std::fs::read_to_string(dest.join("summary.json")).unwrap(),
            "second summary.json"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_held_lock_refuses_a_second_writer_and_stale_temporaries_go() {
        let d = scratch("lock");
        let dest = d.join("run");
        let lock = FolderLock::acquire(&dest).unwrap();
        assert!(FolderLock::try_acquire(&dest).unwrap().is_none());
        let e = FolderLock::acquire(&dest).unwrap_err().to_string();
        assert!(e.contains("another applesim process is writing"), "{e}");
        drop(lock);
        // Leftovers of killed writers (a staged set, a failure record being written, an old
        // set moved aside with the folder missing), and a neighbour's files that stay.
        std::fs::create_dir_all(d.join(".run.tmp-1-0")).unwrap();
        std::fs::write(d.join(".run.failed.json.tmp-1"), "{").unwrap();
        std::fs::create_dir_all(d.join(".run.old-1-3")).unwrap();
        std::fs::write(d.join(".run.old-1-3/summary.json"), "old").unwrap();
        std::fs::create_dir_all(d.join(".runner.tmp-1-0")).unwrap();
        std::fs::write(d.join(".run.notes"), "mine").unwrap();
        let lock = FolderLock::acquire(&dest).unwrap();
        assert_eq!(lock.remove_stale().unwrap(), 2);
        assert_eq!(
            std::fs::read_to_string(dest.join("summary.json")).unwrap(),
            "old"
        );
        drop(lock);
        assert_eq!(listing(&d), [".run.notes", ".runner.tmp-1-0", "run"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn folders_that_are_not_a_run_are_refused() {
        let d = scratch("refuse");
        let mine = d.join("mine");
        std::fs::create_dir_all(&mine).unwrap();
        std::fs::write(mine.join("thesis.tex"), "x").unwrap();
        let lock = FolderLock::acquire(&mine).unwrap();
        let e = StagedFolder::begin(&lock, csv_or_json)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("and no summary.json") && e.contains("leaves this one alone"),
            "{e}"
        );
        std::fs::write(mine.join("summary.json"), "{}").unwrap();
        let e = StagedFolder::begin(&lock, csv_or_json)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("'thesis.tex'"), "{e}");
        drop(lock);
        let file = d.join("file");
        std::fs::write(&file, "x").unwrap();
        let lock = FolderLock::acquire(&file).unwrap();
        let e = StagedFolder::begin(&lock, csv_or_json)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("is a file"), "{e}");
        drop(lock);
        assert_eq!(listing(&d), ["file", "mine"]);
        assert_eq!(listing(&mine), ["summary.json", "thesis.tex"]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
