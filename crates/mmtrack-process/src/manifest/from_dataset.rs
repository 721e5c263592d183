//! A manifest written from a dataset folder (`mmtrack process manifest
//! <campaign.toml> --from <root> --layout oxford|boreas|mulran`): per
//! sequence found, an ingest task and the odometry task that needs it.
//!
//! A sequence is a folder the layout's reader of `mmtrack_ingest` opens
//! ([`OxfordFolder::open`], [`BoreasFolder::open`], [`MulranFolder::open`]):
//! `<root>` itself when it is one, else each sub-folder of `<root>` that
//! holds the layout's scan folder (`radar/` for Oxford and Boreas,
//! `sensor_data/radar/polar/` for MulRan), in name order. Sub-folders
//! without it are skipped and listed; one with it that does not open is an
//! error naming it, so a broken sequence is not silently left out.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mmtrack_ingest::boreas::BoreasFolder;
use mmtrack_ingest::mulran::MulranFolder;
use mmtrack_ingest::oxford::OxfordFolder;

/// The dataset layouts `--from` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// Oxford Radar RobotCar: `radar/<t_us>.png`, `radar.timestamps`.
    Oxford,
    /// Boreas: `radar/<t_us>.png`, `applanix/radar_poses.csv`.
    Boreas,
    /// MulRan: `sensor_data/radar/polar/<t_ns>.png`, `global_pose.csv`.
    Mulran,
}

impl Layout {
    /// The `mmtrack ingest` kind.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Oxford => "oxford",
            Self::Boreas => "boreas",
            Self::Mulran => "mulran",
        }
    }

    /// The layout named `name`.
    ///
    /// # Errors
    /// An unknown name.
    pub fn parse(name: &str) -> anyhow::Result<Self> {
        Ok(match name {
            "oxford" => Self::Oxford,
            "boreas" => Self::Boreas,
            "mulran" => Self::Mulran,
            other => bail!("--layout {other}: expected oxford, boreas or mulran"),
        })
    }

    /// The scan folder that marks a sequence of this layout.
    fn scan_dir(self) -> &'static str {
        match self {
            Self::Oxford | Self::Boreas => "radar",
            Self::Mulran => "sensor_data/radar/polar",
        }
    }

    /// The sequence id of the folder `dir`, opened by the layout's reader.
    fn open(self, dir: &Path) -> anyhow::Result<String> {
        Ok(match self {
            Self::Oxford => OxfordFolder::open(dir)?.sequence_id(),
            Self::Boreas => BoreasFolder::open(dir)?.sequence_id(),
            Self::Mulran => MulranFolder::open(dir)?.sequence_id(),
        })
    }
}

/// One sequence found under a dataset root.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sequence {
    /// Its folder (`<root>` or `<root>/<name>`, as given).
    pub dir: PathBuf,
    /// Its sequence id (the folder name).
    pub id: String,
}

/// What [`find_sequences`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Found {
    /// The sequences, in folder-name order.
    pub sequences: Vec<Sequence>,
    /// Sub-folders that are not sequences of the layout, in name order.
    pub skipped: Vec<PathBuf>,
}

/// The sequences of `layout` under `root`.
///
/// # Errors
/// `root` cannot be listed, a sequence folder does not open (naming it),
/// or no sequence is found.
pub fn find_sequences(root: &Path, layout: Layout) -> anyhow::Result<Found> {
    if root.join(layout.scan_dir()).is_dir() {
        let id = layout.open(root)?;
        return Ok(Found { sequences: vec![Sequence { dir: root.to_path_buf(), id }], skipped: Vec::new() });
    }
    let listing = || format!("{}: cannot list the dataset folder", root.display());
    let mut dirs = Vec::new();
    for entry in std::fs::read_dir(root).with_context(listing)? {
        let path = entry.with_context(listing)?.path();
        if path.is_dir() {
            dirs.push(path);
        }
    }
    dirs.sort();
    let mut found = Found { sequences: Vec::new(), skipped: Vec::new() };
    for dir in dirs {
        if dir.join(layout.scan_dir()).is_dir() {
            let id = layout.open(&dir)?;
            found.sequences.push(Sequence { dir, id });
        } else {
            found.skipped.push(dir);
        }
    }
    if found.sequences.is_empty() {
        bail!(
            "{}: no {} sequence found (a sequence folder holds {}/; looked at the folder and its sub-folders)",
            root.display(),
            layout.name(),
            layout.scan_dir()
        );
    }
    let mut ids: Vec<&str> = found.sequences.iter().map(|s| s.id.as_str()).collect();
    ids.sort_unstable();
    if let Some(pair) = ids.windows(2).find(|w| w[0] == w[1]) {
        bail!("{}: two sequences have the id '{}'", root.display(), pair[0]);
    }
    Ok(found)
}

/// The manifest text for `sequences`: per sequence an ingest task writing
/// `<recordings>/<id>.mcap` and an odometry task (`--preset preset`) that
/// needs it. Paths are written as given (relative ones are relative to the
/// directory the manifest runs in).
#[must_use]
pub fn manifest_text(layout: Layout, sequences: &[Sequence], recordings: &Path, preset: &str) -> String {
    let quote = |s: &str| toml::Value::String(s.to_string()).to_string();
    let mut text = format!(
        "# Written by `mmtrack process manifest --from ... --layout {}`: per sequence, an ingest\n\
         # task and the odometry task that needs it. Run it with\n\
         #   mmtrack process manifest <this file> -o <tables> [--skip-existing]\n",
        layout.name()
    );
    for s in sequences {
        let recording = recordings.join(format!("{}.mcap", s.id)).display().to_string();
        let dir = s.dir.display().to_string();
        text.push_str(&format!(
            "\n[[task]]\nname = {}\nstep = \"ingest\"\nargs = [{}, {}, \"-o\", {}]\n\n\
             [[task]]\nname = {}\nneeds = [{}]\nargs = [\"odometry\", {}, \"--preset\", {}]\n",
            quote(&format!("ingest-{}", s.id)),
            quote(layout.name()),
            quote(&dir),
            quote(&recording),
            quote(&format!("odometry-{}", s.id)),
            quote(&format!("ingest-{}", s.id)),
            quote(&recording),
            quote(preset),
        ));
    }
    text
}
