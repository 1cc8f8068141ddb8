//! Where the loaders read their files: bounded reads, so that a file named by mistake (a
//! recording, a disk image) is refused without being read whole into memory.

use std::io::Read;
use std::path::Path;

/// Where the scene loader reads the scene file and the assets it names
/// ([`crate::load_scene_from`]) and the caustic bake reader
/// ([`crate::caustics::read_bake`]): the file system ([`DiskFiles`]) for every command; another
/// implementation keeps the files in memory, as the fuzz target does.
pub trait SceneFiles {
    /// The whole file at `path`, refusing one larger than `limit` bytes without reading it
    /// whole (an error of kind `InvalidData` whose message ends with `what`, which says what
    /// the file should be); `NotFound` when there is none.
    fn read_bounded(&self, path: &Path, limit: u64, what: &str) -> std::io::Result<Vec<u8>>;
}

/// The file system: what [`crate::load_scene`] and the bake reader read from.
#[derive(Clone, Copy, Debug, Default)]
pub struct DiskFiles;

impl SceneFiles for DiskFiles {
    fn read_bounded(&self, path: &Path, limit: u64, what: &str) -> std::io::Result<Vec<u8>> {
        let too_large = || {
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("larger than {} KiB; {what}", limit / 1024),
            )
        };
        let file = std::fs::File::open(path)?;
        // The size on disk refuses a large file at once; reading at most one byte past the
        // limit catches one that grows while it is read.
        if file.metadata()?.len() > limit {
            return Err(too_large());
        }
        let mut bytes = Vec::new();
        file.take(limit + 1).read_to_end(&mut bytes)?;
        if bytes.len() as u64 > limit {
            return Err(too_large());
        }
        Ok(bytes)
    }
}
