//! The work of one run, identical on the device and on the host: parse the hierarchy in place,
//! fly eight frames of the peer orbit with a cut for a triangle budget (5,000 by default), hash
//! each frame.
//!
//! Each frame is adapted and drawn through the facade (`vdlod::adapt`, `vdlod::draw_bands`):
//! 320x240 by default, in bands of 16 rows, byte-swapped Rgb565 as an SPI panel takes it, 16-bit
//! depth, triangles binned by row once per frame. Everything large is a `static` (the cut, the raster scratch, the bins and
//! one band), so it lands in `.bss` and the symbol table shows what each costs; nothing big ever
//! passes through the stack, and the vertices are read from the hierarchy in flash, never copied.

use core::fmt;
use core::ptr::addr_of_mut;
use core::sync::atomic::{AtomicBool, Ordering};

use vdlod::prelude::*;
use vdlod_core::cut::CutError;
use vdlod_core::format::FormatError;

use crate::clock::Span;

/// Frames flown.
pub const FRAMES: u32 = 8;
/// Frames per revolution of the orbit (frame `i` is at azimuth `2 pi i / 36`).
pub const ORBIT_STEPS: u32 = 36;
// TRIANGLES, VERTICES, QUEUE, WIDTH and HEIGHT, from build.rs (5,000 triangles at 320x240 unless
// the build says otherwise).
include!(concat!(env!("OUT_DIR"), "/config.rs"));
/// Geomorph length in frames.
pub const GEOMORPH_FRAMES: u16 = 4;
/// Rows per band.
pub const BAND_ROWS: usize = 16;

/// The cut of this firmware.
pub type FirmwareCut = Cut<VERTICES, TRIANGLES, QUEUE>;

/// One line of output. [`fmt::Display`] gives the exact text, the same on both targets.
#[derive(Clone, Copy, Debug)]
pub enum Report {
    /// The hierarchy was parsed (and validated).
    Hierarchy {
        /// File size.
        bytes: usize,
        /// Nodes.
        nodes: u32,
        /// Input vertices.
        leaves: u32,
        /// Triangles of the base mesh.
        base_triangles: u32,
    },
    /// Instructions `HierarchyView::parse` took (device only).
    Parse {
        /// Instructions.
        instructions: u64,
    },
    /// One frame's hash: the line the host and the device must agree on.
    Frame {
        /// Frame number from 0.
        frame: u32,
        /// FNV-1a 64 of the cut's triangles, its vertices' position bits and the pixels.
        hash: u64,
        /// Triangles of the cut after adaptation.
        triangles: u32,
        /// The budget or a capacity of the cut held detail back: the frame is coarser than the
        /// policy asked, never missing.
        limited: bool,
    },
    /// What one frame cost (device only).
    Cost {
        /// Frame number from 0.
        frame: u32,
        /// Instructions of `Cut::adapt`.
        adapt: u64,
        /// Instructions of shading, binning, clearing and drawing the bands (hashing them excluded).
        draw: u64,
    },
    /// The run finished.
    Done {
        /// Frames flown.
        frames: u32,
    },
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Report::Hierarchy {
                bytes,
                nodes,
                leaves,
                base_triangles,
            } => write!(
                f,
                "hierarchy_bytes={bytes} nodes={nodes} leaves={leaves} base_triangles={base_triangles}"
            ),
            Report::Parse { instructions } => write!(f, "parse_instructions={instructions}"),
            Report::Frame {
                frame,
                hash,
                triangles,
                limited,
            } => write!(
                f,
                "frame={frame} hash={hash:016x} triangles={triangles} limited={}",
                limited as u8
            ),
            Report::Cost { frame, adapt, draw } => write!(
                f,
                "cost frame={frame} adapt_instructions={adapt} draw_instructions={draw}"
            ),
            Report::Done { frames } => write!(f, "frames={frames} status=ok"),
        }
    }
}

/// Why a run stopped.
#[derive(Clone, Copy, Debug)]
pub enum RunError {
    /// The embedded hierarchy is not valid.
    Format(FormatError),
    /// The base mesh does not fit the cut.
    Cut(CutError),
    /// A frame could not be adapted or drawn.
    Frame(FrameError),
    /// [`run_frames`] ran a second time (its statics are taken once).
    AlreadyRan,
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Format(e) => write!(f, "hierarchy: {e}"),
            RunError::Cut(e) => write!(f, "cut: {e}"),
            RunError::Frame(e) => write!(f, "frame: {e}"),
            RunError::AlreadyRan => f.write_str("run_frames runs once"),
        }
    }
}

// The big state. `Cut::new()` is const and all zeros, as are the other initialisers, so all of
// it is `.bss`.
static mut CUT: FirmwareCut = Cut::new();
static mut SCRATCH: [ShadedVertex; VERTICES] = [ShadedVertex::ZERO; VERTICES];
static mut BINS: [u32; TRIANGLES] = [0; TRIANGLES];
static mut BAND_COLOR: [Rgb565Be; WIDTH * BAND_ROWS] = [Rgb565Be([0; 2]); WIDTH * BAND_ROWS];
static mut BAND_DEPTH: [u16; WIDTH * BAND_ROWS] = [0; WIDTH * BAND_ROWS];
static TAKEN: AtomicBool = AtomicBool::new(false);

/// What drawing needs besides the cut: the rasterizer's scratch, the row bins and one band.
struct DrawBuffers {
    scratch: &'static mut [ShadedVertex; VERTICES],
    bins: &'static mut [u32; TRIANGLES],
    color: &'static mut [Rgb565Be; WIDTH * BAND_ROWS],
    depth: &'static mut [u16; WIDTH * BAND_ROWS],
}

/// The statics, once per program (`None` afterwards).
fn take_statics() -> Option<(&'static mut FirmwareCut, DrawBuffers)> {
    if TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    // SAFETY: `TAKEN` lets this block run at most once per program, and nothing else in the
    // program names these statics, so the references made here are the only ones that ever
    // exist: no aliasing. `addr_of_mut!` makes them without an intermediate reference.
    unsafe {
        Some((
            &mut *addr_of_mut!(CUT),
            DrawBuffers {
                scratch: &mut *addr_of_mut!(SCRATCH),
                bins: &mut *addr_of_mut!(BINS),
                color: &mut *addr_of_mut!(BAND_COLOR),
                depth: &mut *addr_of_mut!(BAND_DEPTH),
            },
        ))
    }
}

/// FNV-1a, 64 bits.
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

/// Runs the frames, handing each output line to `report`. Never inlined: merged into the
/// caller's frame it would keep its locals live under every adaptation and draw (3.3 KB more peak
/// stack, measured with `-Z emit-stack-sizes` once the rasterizer's two triangle loops became
/// one and the inliner changed its mind).
#[inline(never)]
pub fn run_frames(bytes: &[u8], report: &mut impl FnMut(Report)) -> Result<(), RunError> {
    let span = Span::start();
    let h = HierarchyView::parse(bytes).map_err(RunError::Format)?;
    let parse = span.instructions();
    report(Report::Hierarchy {
        bytes: h.size(),
        nodes: h.nodes(),
        leaves: h.leaves(),
        base_triangles: h.base_triangles(),
    });
    if let Some(instructions) = parse {
        report(Report::Parse { instructions });
    }

    let (cut, draw) = take_statics().ok_or(RunError::AlreadyRan)?;
    cut.reset(&h).map_err(RunError::Cut)?;
    cut.set_geomorph_frames(GEOMORPH_FRAMES);
    let policy = QRefine::new(1.0);
    let budget = Budget {
        max_triangles: TRIANGLES as u32,
        ..Budget::default()
    };
    let (center, radius) = h.bounding_sphere();
    let orbit = Orbit::peer(center.into(), radius, ORBIT_STEPS).viewport(WIDTH, HEIGHT);
    let style = Style::default();

    for frame in 0..FRAMES {
        let camera = orbit.camera(frame);

        let span = Span::start();
        let stats = vdlod::adapt(cut, &h, &camera, &policy, &budget).map_err(RunError::Frame)?;
        let adapt = span.instructions();

        // The hash covers the cut (triangles and vertex positions, geomorphs applied) and every
        // pixel of every band, in order.
        let mut hash = Fnv::new();
        for t in cut.triangles() {
            for &c in t {
                hash.write(&c.to_le_bytes());
            }
        }
        for slot in 0..cut.vertex_count() {
            for c in cut.vertex(&h, slot).position {
                hash.write(&c.to_bits().to_le_bytes());
            }
        }

        let span = Span::start();
        let bands = Bands {
            color: &mut draw.color[..],
            depth: &mut draw.depth[..],
            rows: BAND_ROWS,
            background: Rgb565::from_rgb(24, 26, 32).into(),
            bins: &mut draw.bins[..],
        };
        // Hashing a band is part of the flush: a device would send it to its panel here.
        let mut hashing = 0u64;
        vdlod::draw_bands(
            bands,
            cut,
            &h,
            &camera,
            &style,
            &mut draw.scratch[..],
            |band| {
                let s = Span::start();
                for row in 0..band.area().height {
                    for p in band.row(row) {
                        hash.write(&p.0);
                    }
                }
                hashing += s.instructions().unwrap_or(0);
            },
        )
        .map_err(RunError::Frame)?;
        let drawn = span.instructions().map(|d| d.saturating_sub(hashing));

        report(Report::Frame {
            frame,
            hash: hash.0,
            triangles: stats.triangles,
            limited: stats.budget_limited || stats.capacity_limited || stats.queue_overflow,
        });
        if let (Some(adapt), Some(draw)) = (adapt, drawn) {
            report(Report::Cost { frame, adapt, draw });
        }
    }
    report(Report::Done { frames: FRAMES });
    Ok(())
}
