//! Where commands write, and the promises kept there (`docs/limits.md`, "Guarantees"):
//!
//! - **Standard output**: a closed pipe (`kanegen eval … | head`) ends the run quietly with exit
//!   code 0, like other Unix tools; any other write error is a clean error, never a panic.
//! - **Files** are planned before any work: a path that is a directory, in a directory that does
//!   not exist or cannot be written, or equal to one of the command's inputs is an error before
//!   anything is computed. An existing file is replaced only with `--force`, and never when it is
//!   an input.
//! - Files are written to a temporary name in the same directory and renamed into place, so a
//!   reader sees the old file or the new one, never a mix; a multi-file output (`--out DIR`) is
//!   staged whole before the first rename.

use anyhow::{bail, Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Marks an error that is a closed standard output: the binary exits 0 without a message.
#[derive(Debug)]
pub struct BrokenPipe;

impl std::fmt::Display for BrokenPipe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("standard output closed")
    }
}

impl std::error::Error for BrokenPipe {}

/// Writes `text` to `out` and flushes; a broken pipe becomes [`BrokenPipe`], any other error
/// a clean "cannot write to standard output" error.
///
/// # Errors
/// As above.
pub fn print(out: &mut dyn Write, text: &str) -> Result<()> {
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(BrokenPipe.into()),
        Err(e) => Err(anyhow::Error::new(e).context("cannot write to standard output")),
    }
}

/// Whether `e` (or an error in its chain) is a closed standard output.
#[must_use]
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.is::<BrokenPipe>()
            || c.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Whether two paths name the same existing file (same device and inode, or the same canonical
/// path).
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return x.dev() == y.dev() && x.ino() == y.ino();
        }
    }
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// The directory a file path lives in (`.` for a bare name).
fn parent_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Checks that `dir` is an existing directory we can create files in (by creating and removing
/// a temporary file).
fn check_writable_dir(dir: &Path) -> Result<()> {
    let meta = std::fs::metadata(dir)
        .with_context(|| format!("output directory `{}` does not exist", dir.display()))?;
    if !meta.is_dir() {
        bail!("`{}` is not a directory", dir.display());
    }
    tempfile::Builder::new()
        .prefix(".kanegen-probe-")
        .tempfile_in(dir)
        .map(drop)
        .with_context(|| format!("cannot create files in `{}`", dir.display()))
}

/// Checks one output file path against the rules of the module.
fn check_target(path: &Path, force: bool, inputs: &[PathBuf]) -> Result<()> {
    if let Some(input) = inputs.iter().find(|i| same_file(path, i)) {
        bail!(
            "output `{}` is the input `{}`: refusing to write over it",
            path.display(),
            input.display()
        );
    }
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => bail!("output `{}` is a directory", path.display()),
        Ok(_) if !force => bail!(
            "output `{}` exists (pass --force to replace it)",
            path.display()
        ),
        _ => Ok(()),
    }
}

/// An output file, checked before the work that produces it ([`OutputFile::plan`]).
#[derive(Clone, Debug)]
pub struct OutputFile {
    path: PathBuf,
}

impl OutputFile {
    /// Checks `path` as an output: not a directory, not one of `inputs`, in a writable
    /// directory, and not existing unless `force`.
    ///
    /// # Errors
    /// The first rule broken, naming the path.
    pub fn plan(path: &Path, force: bool, inputs: &[PathBuf]) -> Result<Self> {
        check_target(path, force, inputs)?;
        check_writable_dir(&parent_of(path))?;
        Ok(OutputFile {
            path: path.to_path_buf(),
        })
    }

    /// The path.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes `contents` to a temporary file beside the target and renames it into place.
    ///
    /// # Errors
    /// If the file cannot be written (a full disk), naming it; the target is then untouched.
    pub fn write(&self, contents: &[u8]) -> Result<()> {
        let staged = stage(&self.path, contents)?;
        commit(staged, &self.path)
    }
}

/// A temporary-file builder whose files get the usual permissions (`0666` less the umask), not
/// the private `0600` of temporary files, once renamed into place.
fn builder() -> tempfile::Builder<'static, 'static> {
    let mut b = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b
}

/// Writes `contents` to a temporary file in the target's directory.
fn stage(target: &Path, contents: &[u8]) -> Result<tempfile::NamedTempFile> {
    let mut f = builder()
        .prefix(".kanegen-")
        .tempfile_in(parent_of(target))
        .with_context(|| format!("cannot write `{}`", target.display()))?;
    f.write_all(contents)
        .and_then(|()| f.flush())
        .with_context(|| format!("cannot write `{}`", target.display()))?;
    Ok(f)
}

/// Renames a staged file into place.
fn commit(f: tempfile::NamedTempFile, target: &Path) -> Result<()> {
    f.persist(target)
        .map(drop)
        .map_err(|e| anyhow::Error::new(e.error))
        .with_context(|| format!("cannot write `{}`", target.display()))
}

/// A directory of output files (`--out DIR`), checked before the work that produces them.
#[derive(Clone, Debug)]
pub struct OutputDir {
    dir: PathBuf,
    names: Vec<String>,
    force: bool,
}

impl OutputDir {
    /// Creates `dir` if needed and checks it can hold `names` (the files the command may
    /// write): it is a writable directory, and none of the files exists unless `force`, nor is
    /// one of `inputs`.
    ///
    /// # Errors
    /// The first rule broken, naming the path.
    pub fn plan(dir: &Path, names: &[&str], force: bool, inputs: &[PathBuf]) -> Result<Self> {
        if let Ok(m) = std::fs::metadata(dir) {
            if !m.is_dir() {
                bail!("--out `{}` exists and is not a directory", dir.display());
            }
        }
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create `{}`", dir.display()))?;
        check_writable_dir(dir)?;
        for n in names {
            check_target(&dir.join(n), force, inputs)?;
        }
        Ok(OutputDir {
            dir: dir.to_path_buf(),
            names: names.iter().map(|n| (*n).to_string()).collect(),
            force,
        })
    }

    /// The directory.
    #[must_use]
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// A path in the directory.
    #[must_use]
    pub fn join(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Writes the files: all staged under temporary names first, then renamed into place.
    ///
    /// # Errors
    /// If a file cannot be written; nothing has been renamed then.
    pub fn write_all(&self, files: &[(&str, Vec<u8>)]) -> Result<()> {
        let mut staged = Vec::new();
        for (name, contents) in files {
            debug_assert!(self.names.iter().any(|n| n == name), "{name} not planned");
            let target = self.dir.join(name);
            staged.push((stage(&target, contents)?, target));
        }
        for (f, target) in staged {
            commit(f, &target)?;
        }
        Ok(())
    }

    /// With `--force`, removes the planned files not in `written` (left from an earlier run),
    /// so the directory never holds a mix of two runs.
    ///
    /// # Errors
    /// If an old file cannot be removed.
    pub fn remove_stale(&self, written: &[&str]) -> Result<()> {
        if !self.force {
            return Ok(());
        }
        for n in &self.names {
            if written.iter().any(|w| w == n) {
                continue;
            }
            let p = self.dir.join(n);
            if p.exists() {
                std::fs::remove_file(&p)
                    .with_context(|| format!("cannot remove the old `{}`", p.display()))?;
            }
        }
        Ok(())
    }

    /// A temporary file in the directory, for output written as it is produced (a trajectory),
    /// renamed into place by [`OutputDir::commit_stream`].
    ///
    /// # Errors
    /// If it cannot be created.
    pub fn stream(&self, name: &str) -> Result<tempfile::NamedTempFile> {
        builder()
            .prefix(&format!(".{name}-"))
            .suffix(".partial")
            .tempfile_in(&self.dir)
            .with_context(|| format!("cannot write `{}`", self.dir.join(name).display()))
    }

    /// Renames a streamed file into place as `name`.
    ///
    /// # Errors
    /// If it cannot be flushed or renamed.
    pub fn commit_stream(&self, mut f: tempfile::NamedTempFile, name: &str) -> Result<()> {
        let target = self.dir.join(name);
        f.flush()
            .with_context(|| format!("cannot write `{}`", target.display()))?;
        commit(f, &target)
    }
}
