//! One checkpoint file: a fixed header, an array table, the scene's path, then every particle
//! array, each starting on a 64-byte boundary. `docs/checkpoint-format.md` specifies the bytes.
//!
//! Reading maps the file (memmap2) and checks it whole (length, magic, byte order, version,
//! checksum, table) before anything is used; each array is then copied once, straight from the
//! mapped pages into the particle vector.

use crate::bodies::{Bodies, RigidState};
use crate::particles::{ArrayMut, Kind, Particles};
use memmap2::{Mmap, MmapOptions};
use std::borrow::Cow;
use std::ffi::OsStr;
use std::fs::File;
use std::io::Write;
use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};
use xxhash_rust::xxh3::Xxh3;

const MAGIC: [u8; 8] = *b"ISPHCKPT";
/// Bumped whenever the layout or the meaning of a field changes.
const FORMAT_VERSION: u32 = 1;
/// Written in the writer's byte order; a reader of the other order sees 0x04030201.
const BYTE_ORDER_MARK: u32 = 0x0102_0304;
/// Every array starts at a multiple of this many bytes (a cache line), so the mapped arrays are
/// aligned for any load.
const ALIGN: usize = 64;
/// Bytes of the fixed header; the array table follows it.
const HEADER_LEN: usize = 112;
const ENTRY_LEN: usize = 48;
const NAME_LEN: usize = 24;
/// The checksum covers the file from this offset (just after the checksum field) to its end.
const CHECKSUMMED_FROM: usize = 24;
/// The array of the rigid bodies' states (`RigidState::to_array`, one after the other), in a
/// run with bodies only; the one array whose length is not the particle count.
const BODIES: &str = "bodies";

/// What a continued run needs besides the particle arrays.
#[derive(Clone, Debug, PartialEq)]
pub struct RunState {
    pub step: u64,
    pub time: f64,
    /// Δt of the last step (0 before the first): a sliver of a step after it takes the
    /// divergence the particles carry into it out over it (`StepLength::carried_time`).
    pub dt: f64,
    /// Wall-clock seconds the run had taken; stats.csv continues from there.
    pub wall_seconds: f64,
    /// Frames in particles.h5 at this state.
    pub frames_written: u64,
    /// The next frame falls at `next_output × output_interval` (or at the end time before it).
    pub next_output: u64,
    /// `Scene::content_hash` of the scene the run was stepping with.
    pub scene_hash: u64,
    /// The scene file, as an absolute path.
    pub scene_path: PathBuf,
}

#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("cannot read checkpoint {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot write checkpoint {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path} is truncated: it holds {actual} of its {expected} bytes (the copy or the write was cut short); resume from an older checkpoint of the run, or give `isph resume` the output directory to pick the newest valid one")]
    Truncated {
        path: PathBuf,
        actual: u64,
        expected: u64,
    },
    #[error("{path} is not an isph checkpoint: it does not start with the bytes `ISPHCKPT`")]
    WrongMagic { path: PathBuf },
    #[error("{path} was written on a machine of the other byte order; this isph reads only checkpoints of its own byte order")]
    ForeignByteOrder { path: PathBuf },
    #[error("{path} has checkpoint format version {version}, newer than the version {FORMAT_VERSION} this isph reads; resume it with the isph that wrote it (or a later one)")]
    NewerVersion { path: PathBuf, version: u32 },
    #[error("{path} has checkpoint format version {version}, which no isph ever wrote (this isph reads version {FORMAT_VERSION}): the file is damaged")]
    UnknownVersion { path: PathBuf, version: u32 },
    #[error("{path} is damaged: its checksum is {stored:#018x} but its content hashes to {computed:#018x}; resume from an older checkpoint of the run, or give `isph resume` the output directory to pick the newest valid one")]
    BadChecksum {
        path: PathBuf,
        stored: u64,
        computed: u64,
    },
    #[error("{path} is damaged although its checksum matches: {what}")]
    Malformed { path: PathBuf, what: String },
    #[error("{path} does not fit this isph's particles: {what}; resume it with the isph version that wrote it")]
    Mismatch { path: PathBuf, what: String },
}

impl CheckpointError {
    /// Whether the file itself is damaged (cut short, overwritten, corrupted), as opposed to a
    /// sound checkpoint this isph cannot read: of a newer format, of the other byte order, of
    /// other particles, or behind an error of the file system.
    pub fn is_damage(&self) -> bool {
        matches!(
            self,
            CheckpointError::Truncated { .. }
                | CheckpointError::WrongMagic { .. }
                | CheckpointError::UnknownVersion { .. }
                | CheckpointError::BadChecksum { .. }
                | CheckpointError::Malformed { .. }
        )
    }
}

/// How the elements of an array are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ElementType {
    F64 = 1,
    U64 = 2,
    U16 = 3,
    U8 = 4,
}

impl ElementType {
    fn from_code(code: u32) -> Option<Self> {
        [Self::F64, Self::U64, Self::U16, Self::U8]
            .into_iter()
            .find(|t| *t as u32 == code)
    }

    fn size(self) -> usize {
        match self {
            Self::F64 | Self::U64 => 8,
            Self::U16 => 2,
            Self::U8 => 1,
        }
    }
}

/// One row of the array table.
#[derive(Clone, Debug)]
struct Entry {
    name: String,
    element: ElementType,
    offset: usize,
    length: usize,
}

impl Entry {
    fn end(&self) -> usize {
        self.offset + self.length * self.element.size()
    }
}

fn align_up(n: usize) -> usize {
    n.div_ceil(ALIGN) * ALIGN
}

/// The stored bytes of one array: the vector itself, except `Kind`, which is stored as its u8 code.
fn stored_bytes<'a>(array: &'a ArrayMut<'_>) -> (ElementType, Cow<'a, [u8]>) {
    match array {
        ArrayMut::F64(v) => (ElementType::F64, Cow::Borrowed(bytemuck::cast_slice(v))),
        ArrayMut::U64(v) => (ElementType::U64, Cow::Borrowed(bytemuck::cast_slice(v))),
        ArrayMut::U16(v) => (ElementType::U16, Cow::Borrowed(bytemuck::cast_slice(v))),
        ArrayMut::U8(v) => (ElementType::U8, Cow::Borrowed(v.as_slice())),
        ArrayMut::Kind(v) => (
            ElementType::U8,
            Cow::Owned(v.iter().map(|&k| k as u8).collect()),
        ),
    }
}

/// Little helpers to put and get header fields in the writer's (native) byte order.
fn put(buf: &mut [u8], at: usize, bytes: &[u8]) {
    buf[at..at + bytes.len()].copy_from_slice(bytes);
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_ne_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_ne_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}

fn f64_at(b: &[u8], at: usize) -> f64 {
    f64::from_bits(u64_at(b, at))
}

/// The header, array table and scene path, zero-padded to the first array, with the checksum
/// field still zero; and the table it describes.
fn head(
    state: &RunState,
    dims: usize,
    count: usize,
    arrays: &[(&str, ElementType, usize)],
) -> (Vec<u8>, Vec<Entry>) {
    let path = state.scene_path.as_os_str().as_bytes();
    let path_at = HEADER_LEN + ENTRY_LEN * arrays.len();
    let data_start = align_up(path_at + path.len());
    let mut entries: Vec<Entry> = Vec::with_capacity(arrays.len());
    for &(name, element, length) in arrays {
        // Names are constants of `Particles::arrays_mut`: a longer one is a programming error.
        assert!(
            name.len() <= NAME_LEN,
            "array name `{name}` is longer than the {NAME_LEN} bytes the format gives it"
        );
        let offset = entries.last().map_or(data_start, |e| align_up(e.end()));
        entries.push(Entry {
            name: name.to_owned(),
            element,
            offset,
            length,
        });
    }
    let file_length = entries.last().map_or(data_start, Entry::end);

    let mut h = vec![0u8; data_start];
    put(&mut h, 0, &MAGIC);
    put(&mut h, 8, &FORMAT_VERSION.to_ne_bytes());
    put(&mut h, 12, &BYTE_ORDER_MARK.to_ne_bytes());
    put(&mut h, 24, &(file_length as u64).to_ne_bytes());
    put(&mut h, 32, &(dims as u32).to_ne_bytes());
    put(&mut h, 36, &(arrays.len() as u32).to_ne_bytes());
    put(&mut h, 40, &(count as u64).to_ne_bytes());
    put(&mut h, 48, &state.step.to_ne_bytes());
    put(&mut h, 56, &state.time.to_bits().to_ne_bytes());
    put(&mut h, 64, &state.dt.to_bits().to_ne_bytes());
    put(&mut h, 72, &state.wall_seconds.to_bits().to_ne_bytes());
    put(&mut h, 80, &state.frames_written.to_ne_bytes());
    put(&mut h, 88, &state.next_output.to_ne_bytes());
    put(&mut h, 96, &state.scene_hash.to_ne_bytes());
    put(&mut h, 104, &(path.len() as u32).to_ne_bytes());
    for (k, e) in entries.iter().enumerate() {
        let at = HEADER_LEN + k * ENTRY_LEN;
        put(&mut h, at, e.name.as_bytes());
        put(&mut h, at + 24, &(e.element as u32).to_ne_bytes());
        put(&mut h, at + 32, &(e.offset as u64).to_ne_bytes());
        put(&mut h, at + 40, &(e.length as u64).to_ne_bytes());
    }
    put(&mut h, path_at, path);
    (h, entries)
}

/// The bytes that follow the head (`head_len` bytes) in the file: each array after the zero
/// padding that brings it to its offset.
fn array_chunks<'a>(
    head_len: usize,
    entries: &'a [Entry],
    arrays: &'a [Cow<'a, [u8]>],
) -> impl Iterator<Item = &'a [u8]> {
    static ZEROS: [u8; ALIGN] = [0; ALIGN];
    let previous_ends = std::iter::once(head_len).chain(entries.iter().map(Entry::end));
    entries
        .iter()
        .zip(previous_ends)
        .zip(arrays)
        .flat_map(|((entry, end), bytes)| [&ZEROS[..entry.offset - end], &bytes[..]])
}

/// Writes the checkpoint of `state`, `p` and the bodies' states `bodies`
/// (`Bodies::states`, empty without bodies) into `file` (empty, positioned at its start).
/// `p` is borrowed mutably only because `Particles::arrays_mut` is the one list of its arrays;
/// nothing in it changes.
pub fn write<const D: usize>(
    file: &mut File,
    state: &RunState,
    p: &mut Particles<D>,
    bodies: &[f64],
) -> std::io::Result<()> {
    let count = p.len();
    let arrays = p.arrays_mut();
    let stored: Vec<_> = arrays.iter().map(|(_, a)| stored_bytes(a)).collect();
    let mut table: Vec<_> = arrays
        .iter()
        .zip(&stored)
        .map(|((name, _), (element, _))| (*name, *element, count))
        .collect();
    let mut bytes: Vec<Cow<[u8]>> = stored.into_iter().map(|(_, b)| b).collect();
    if !bodies.is_empty() {
        table.push((BODIES, ElementType::F64, bodies.len()));
        bytes.push(Cow::Borrowed(bytemuck::cast_slice(bodies)));
    }
    let (mut head, entries) = head(state, D, count, &table);

    let mut hasher = Xxh3::new();
    hasher.update(&head[CHECKSUMMED_FROM..]);
    for chunk in array_chunks(head.len(), &entries, &bytes) {
        hasher.update(chunk);
    }
    put(&mut head, 16, &hasher.digest().to_ne_bytes());
    file.write_all(&head)?;
    for chunk in array_chunks(head.len(), &entries, &bytes) {
        file.write_all(chunk)?;
    }
    Ok(())
}

/// A checkpoint file, mapped and checked.
pub struct Checkpoint {
    path: PathBuf,
    map: Mmap,
    dimensions: usize,
    entries: Vec<Entry>,
    pub state: RunState,
}

impl Checkpoint {
    /// Maps `path` and checks it: length, magic, byte order, version, checksum and table.
    pub fn open(path: &Path) -> Result<Self, CheckpointError> {
        let read_error = |source| CheckpointError::Read {
            path: path.to_owned(),
            source,
        };
        let file = File::open(path).map_err(read_error)?;
        let len = file.metadata().map_err(read_error)?.len();
        if len < HEADER_LEN as u64 {
            return Err(CheckpointError::Truncated {
                path: path.to_owned(),
                actual: len,
                expected: HEADER_LEN as u64,
            });
        }
        // Populated: every byte is read (checksum, then copy), so the kernel maps and reads
        // ahead the whole file at once instead of one page fault at a time.
        // SAFETY: the map is only read. Checkpoints are never changed in place (they are
        // written under a temporary name and renamed), so its pages do not change under it.
        let map = unsafe { MmapOptions::new().populate().map(&file) }.map_err(read_error)?;
        check_identity(path, &map)?;
        let expected = u64_at(&map, 24);
        if (map.len() as u64) < expected {
            return Err(CheckpointError::Truncated {
                path: path.to_owned(),
                actual: map.len() as u64,
                expected,
            });
        }
        let malformed = |what: String| CheckpointError::Malformed {
            path: path.to_owned(),
            what,
        };
        if map.len() as u64 > expected {
            return Err(malformed(format!(
                "it holds {} bytes after the {expected} its header declares",
                map.len() as u64 - expected
            )));
        }
        let stored = u64_at(&map, 16);
        let computed = xxhash_rust::xxh3::xxh3_64(&map[CHECKSUMMED_FROM..]);
        if stored != computed {
            return Err(CheckpointError::BadChecksum {
                path: path.to_owned(),
                stored,
                computed,
            });
        }
        let (dimensions, entries, state) = parse_layout(&map).map_err(malformed)?;
        Ok(Self {
            path: path.to_owned(),
            map,
            dimensions,
            entries,
            state,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn dimensions(&self) -> usize {
        self.dimensions
    }

    /// Replaces every array of `p` by the checkpoint's (in the stored particle order). On error
    /// `p` may be partly replaced and must be dropped.
    pub fn restore<const D: usize>(&self, p: &mut Particles<D>) -> Result<(), CheckpointError> {
        let mismatch = |what: String| CheckpointError::Mismatch {
            path: self.path.clone(),
            what,
        };
        if self.dimensions != D {
            return Err(mismatch(format!(
                "it holds a {}D run, not {D}D",
                self.dimensions
            )));
        }
        let arrays = p.arrays_mut();
        if let Some(extra) = self
            .entries
            .iter()
            .find(|e| e.name != BODIES && !arrays.iter().any(|(name, _)| *name == e.name))
        {
            return Err(mismatch(format!(
                "it holds an array `{}` this isph does not know",
                extra.name
            )));
        }
        for (name, array) in arrays {
            let entry = self
                .entries
                .iter()
                .find(|e| e.name == name)
                .ok_or_else(|| mismatch(format!("it lacks the array `{name}`")))?;
            let (element, _) = stored_bytes(&array);
            if entry.element != element {
                return Err(mismatch(format!(
                    "its array `{name}` holds {:?} elements, not {element:?}",
                    entry.element
                )));
            }
            let bytes = &self.map[entry.offset..entry.end()];
            match array {
                ArrayMut::F64(v) => replace(v, bytes),
                ArrayMut::U64(v) => replace(v, bytes),
                ArrayMut::U16(v) => replace(v, bytes),
                ArrayMut::U8(v) => replace(v, bytes),
                ArrayMut::Kind(v) => {
                    *v = bytes
                        .iter()
                        .map(|&code| Kind::from_code(code))
                        .collect::<Option<_>>()
                        .ok_or_else(|| {
                            mismatch(format!("its array `{name}` holds an unknown particle kind"))
                        })?;
                }
            }
        }
        if !ids_are_a_permutation(&p.id) {
            return Err(CheckpointError::Malformed {
                path: self.path.clone(),
                what: "its particle ids are not 0, 1, …, N−1 in some order".into(),
            });
        }
        Ok(())
    }
}

impl Checkpoint {
    /// Restores the states of `bodies` (those of the run's scene): refused if the checkpoint
    /// holds no state for each of them, or holds states where the scene has no body.
    pub fn restore_bodies(&self, bodies: &mut Bodies) -> Result<(), CheckpointError> {
        let mismatch = |what: String| CheckpointError::Mismatch {
            path: self.path.clone(),
            what,
        };
        let entry = self.entries.iter().find(|e| e.name == BODIES);
        let states: Vec<f64> = match entry {
            Some(e) if e.element == ElementType::F64 => {
                let mut states = Vec::new();
                replace(&mut states, &self.map[e.offset..e.end()]);
                states
            }
            Some(_) => return Err(mismatch(format!("its array `{BODIES}` does not hold f64"))),
            None => Vec::new(),
        };
        if !bodies.restore(&states) {
            return Err(mismatch(format!(
                "it holds the states of {} bodies, the scene has {}",
                states.len() / RigidState::LEN,
                bodies.bodies.len()
            )));
        }
        Ok(())
    }
}

/// v ← the elements stored in `bytes`, viewed in place: `parse_layout` checked that they start
/// on a 64-byte boundary of the (page-aligned) map and hold whole elements.
fn replace<T: bytemuck::Pod>(v: &mut Vec<T>, bytes: &[u8]) {
    v.clear();
    v.extend_from_slice(bytemuck::cast_slice(bytes));
}

fn ids_are_a_permutation(ids: &[u64]) -> bool {
    let mut seen = vec![false; ids.len()];
    ids.iter().all(|&id| {
        let fresh = (id as usize) < ids.len() && !seen[id as usize];
        if fresh {
            seen[id as usize] = true;
        }
        fresh
    })
}

/// Magic, byte order and version: what must hold before any other field can be read.
fn check_identity(path: &Path, b: &[u8]) -> Result<(), CheckpointError> {
    let path = path.to_owned();
    if b[..8] != MAGIC {
        return Err(CheckpointError::WrongMagic { path });
    }
    if u32_at(b, 12) != BYTE_ORDER_MARK {
        return Err(CheckpointError::ForeignByteOrder { path });
    }
    match u32_at(b, 8) {
        FORMAT_VERSION => Ok(()),
        version if version > FORMAT_VERSION => Err(CheckpointError::NewerVersion { path, version }),
        version => Err(CheckpointError::UnknownVersion { path, version }),
    }
}

type Layout = (usize, Vec<Entry>, RunState);

/// The header fields and array table of a file whose checksum matched; an error says what is
/// inconsistent.
fn parse_layout(b: &[u8]) -> Result<Layout, String> {
    let dims = u32_at(b, 32) as usize;
    let array_count = u32_at(b, 36) as usize;
    let count = u64_at(b, 40) as usize;
    let path_len = u32_at(b, 104) as usize;
    if !(dims == 2 || dims == 3) {
        return Err(format!("its dimension is {dims}"));
    }
    let path_at = HEADER_LEN + ENTRY_LEN * array_count;
    let data_start = align_up(path_at + path_len);
    if data_start > b.len() {
        return Err(format!(
            "its table of {array_count} arrays runs past the end"
        ));
    }
    let mut entries = Vec::with_capacity(array_count);
    for k in 0..array_count {
        let at = HEADER_LEN + k * ENTRY_LEN;
        let name_bytes = &b[at..at + NAME_LEN];
        let name_len = name_bytes.iter().position(|&c| c == 0).unwrap_or(NAME_LEN);
        let name = std::str::from_utf8(&name_bytes[..name_len])
            .map_err(|_| format!("array {k} has a name that is not UTF-8"))?
            .to_owned();
        let code = u32_at(b, at + 24);
        let element = ElementType::from_code(code)
            .ok_or_else(|| format!("array `{name}` has element type {code}"))?;
        let entry = Entry {
            name,
            element,
            offset: u64_at(b, at + 32) as usize,
            length: u64_at(b, at + 40) as usize,
        };
        let starts_after = entries.last().map_or(data_start, Entry::end);
        if entry.offset % ALIGN != 0
            || entry.offset < starts_after
            || (entry.length != count && entry.name != BODIES)
            || entry
                .length
                .checked_mul(element.size())
                .and_then(|n| n.checked_add(entry.offset))
                .is_none_or(|end| end > b.len())
        {
            return Err(format!(
                "array `{}` (offset {}, {} elements) does not fit the layout of {count} particles",
                entry.name, entry.offset, entry.length
            ));
        }
        entries.push(entry);
    }
    let state = RunState {
        step: u64_at(b, 48),
        time: f64_at(b, 56),
        dt: f64_at(b, 64),
        wall_seconds: f64_at(b, 72),
        frames_written: u64_at(b, 80),
        next_output: u64_at(b, 88),
        scene_hash: u64_at(b, 96),
        scene_path: PathBuf::from(OsStr::from_bytes(&b[path_at..path_at + path_len])),
    };
    Ok((dims, entries, state))
}
