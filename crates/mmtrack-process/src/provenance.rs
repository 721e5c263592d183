//! What a run records about its input files: the canonical absolute path,
//! the size in bytes and a CRC-32 of the content.
//!
//! The path is canonical (absolute, symbolic links and `..` resolved), so the
//! same command run from two working directories records the same words and
//! writes byte-identical tables; size and checksum say which content was
//! read, so a file replaced under the same name is told apart.
//!
//! The checksum is CRC-32 (IEEE 802.3, the zlib/gzip one) from `crc32fast`,
//! already in the dependency tree (the CIR readers check ZIP and zlib
//! members with it). It runs at several GB/s with the PCLMULQDQ/ARMv8 CRC
//! instructions, so reading a recording a second time costs little beside
//! processing it, and anyone can recompute it without mmtrack
//! (`python -c "import zlib; print(f'{zlib.crc32(open(p, \"rb\").read()):08x}')"`).
//! It identifies content, it does not authenticate it (not a cryptographic
//! hash).

use std::io::Read;
use std::path::Path;

use anyhow::Context;
use serde::Serialize;

/// One input file as a run records it in its run configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct InputFile {
    /// The canonical absolute path ([`canonical`]).
    pub path: String,
    /// Size in bytes.
    pub bytes: u64,
    /// CRC-32 (IEEE) of the content, 8 lower-case hex digits.
    pub crc32: String,
}

pub use mmtrack_io::paths::canonical;

/// The path, size and CRC-32 of the file at `path`, read once in 1 MiB
/// blocks.
///
/// # Errors
/// The file cannot be opened or read, naming it.
pub fn input_file(path: &Path) -> anyhow::Result<InputFile> {
    let context = || format!("{}: cannot read the input to record its checksum", path.display());
    let mut file = std::fs::File::open(path).with_context(context)?;
    let mut hasher = crc32fast::Hasher::new();
    let mut buffer = vec![0_u8; 1 << 20];
    let mut bytes = 0_u64;
    loop {
        let n = file.read(&mut buffer).with_context(context)?;
        if n == 0 {
            break;
        }
        hasher.update(&buffer[..n]);
        bytes += n as u64;
    }
    Ok(InputFile { path: canonical(path), bytes, crc32: format!("{:08x}", hasher.finalize()) })
}

/// [`input_file`] of every path that names a file, in order. A source that
/// is no file (a recording simulated in memory by `reproduce`, named by its
/// scenario, e.g. `embedded data/reproduce/odometry-drive.toml`) is left
/// out: there is no content to record.
///
/// # Errors
/// The first file that cannot be read.
pub fn input_files<P: AsRef<Path>>(paths: &[P]) -> anyhow::Result<Vec<InputFile>> {
    paths.iter().map(AsRef::as_ref).filter(|p| p.is_file()).map(input_file).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_files_are_canonical_with_size_and_the_zlib_crc32() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        std::fs::write(dir.path().join("a.bin"), b"123456789").unwrap();
        let direct = input_file(&dir.path().join("a.bin")).unwrap();
        let roundabout = input_file(&dir.path().join("sub/../a.bin")).unwrap();
        assert_eq!(direct, roundabout);
        assert!(Path::new(&direct.path).is_absolute() && !direct.path.contains(".."), "{}", direct.path);
        // The CRC-32 check value of "123456789" (IEEE 802.3 / zlib).
        assert_eq!((direct.bytes, direct.crc32.as_str()), (9, "cbf43926"));
        let err = input_file(&dir.path().join("missing")).unwrap_err();
        assert!(format!("{err:#}").contains("missing: cannot read the input"), "{err:#}");
        // A described source that is no file has nothing to record.
        let described = Path::new("embedded data/reproduce/odometry-drive.toml");
        assert_eq!(input_files(&[dir.path().join("a.bin").as_path(), described]).unwrap(), vec![direct]);
    }
}
