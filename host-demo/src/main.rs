//! `vdlod-demo`: renders meshes with the vdlod rasterizer and writes PNG frames.
//!
//! With no arguments it flies a view-dependent cut of the bundled Stanford bunny around the
//! merge-tree paper's orbit and writes frames, statistics, a plot and a comparison into `./out/`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use vdlod_core::adapt::Budget;
use vdlod_core::build::{BuildOptions, Cost, ErrorBound, Placement};
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::Importance;
use vdlod_core::wavelet::build::{Scheme, SemiRegular};
use vdlod_core::wavelet::SemiRegularView;
use vdlod_demo::camera::{path_cameras, Camera};
use vdlod_demo::hierarchy;
use vdlod_demo::importance;
use vdlod_demo::lod::{self, OrbitOptions, PolicyChoice};
use vdlod_demo::mesh::Bounds;
use vdlod_demo::mesh::{self, load_obj_bytes, IndexedMesh, LoadOptions, Up, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::render::{render_orbit, RenderOptions};
use vdlod_demo::table1;
use vdlod_demo::terrain::{self, FlyOver, Terrain};
use vdlod_demo::terrain_engines;
use vdlod_demo::textures;
use vdlod_demo::wavelet;
use vdlod_raster::Shading;

/// A finite number of at least 0, for tolerances and thresholds.
fn non_negative(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Ok(_) => Err("must be a finite number of at least 0".into()),
        Err(e) => Err(e.to_string()),
    }
}

/// A finite number above 0.
fn positive(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(_) => Err("must be a finite number above 0".into()),
        Err(e) => Err(e.to_string()),
    }
}

/// A terrain's vertical scale: above 0, at most 10.
fn vertical_scale(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= 10.0 => Ok(v),
        Ok(_) => Err("must be a finite number above 0 and at most 10".into()),
        Err(e) => Err(e.to_string()),
    }
}

/// A frame size the rasterizer takes: 1 to 4096 pixels.
fn dimension(text: &str) -> Result<usize, String> {
    let max = vdlod_raster::MAX_DIMENSION;
    match text.parse::<usize>() {
        Ok(v) if (1..=max).contains(&v) => Ok(v),
        Ok(_) => Err(format!("must be 1 to {max} pixels")),
        Err(e) => Err(e.to_string()),
    }
}

/// `println!` through [`say`].
macro_rules! say {
    ($($arg:tt)*) => {
        say(format_args!($($arg)*))
    };
}

/// The mesh file's up axis.
#[derive(Clone, Copy, Default, ValueEnum)]
enum UpArg {
    /// +Y is up.
    #[default]
    Y,
    /// +Z is up (CAD, many scanners): turned a quarter about X so +Z becomes +Y.
    Z,
}

/// How a mesh file is read.
#[derive(clap::Args, Clone, Copy, Default)]
struct InputArgs {
    /// Reject a mesh the builder would reject, with the reason, instead of repairing it.
    #[arg(long)]
    strict: bool,
    /// The mesh file's up axis.
    #[arg(long, value_enum, default_value = "y")]
    up: UpArg,
}

impl InputArgs {
    fn options(self) -> LoadOptions {
        LoadOptions {
            repair: !self.strict,
            up: match self.up {
                UpArg::Y => Up::Y,
                UpArg::Z => Up::Z,
            },
        }
    }
}

#[derive(Parser)]
#[command(
    name = "vdlod-demo",
    version,
    about = "View-dependent LOD demo: renders meshes to PNG frames"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Fly the merge-tree paper's orbit with a view-dependent cut: frames, stats.csv, plot.png,
    /// side_by_side.png (adapted | full detail | difference).
    Orbit(OrbitArgs),
    /// Fly low over a terrain (a heightmap and colormap, or a procedural island) with a
    /// view-dependent cut; writes what `orbit` writes.
    Terrain(TerrainArgs),
    /// Fly the merge-tree paper's orbit around a mesh at full detail and write PNG frames.
    Render(RenderArgs),
    /// Build a mesh's vertex hierarchy and write it as a .vdh file.
    Build(BuildArgs),
    /// Read a mesh (OBJ, OFF, PLY or STL), repair it and write it as OBJ.
    Repair(RepairArgs),
    /// Validate a .vdh hierarchy or .vdw semi-regular file and print its figures.
    Info(InfoArgs),
    /// Write the unit sphere as a semi-regular mesh for the wavelet engine: an octahedron
    /// subdivided LEVELS times (8,192 faces at 5 levels).
    Sphere(SphereArgs),
    /// Subdivide a mesh into a semi-regular one for the wavelet engine: its triangles (or, with
    /// --base, a simplification of it to about that many faces) become the base mesh. With an
    /// output ending in .obj, the mesh itself after LEVELS steps of Loop subdivision (the
    /// merge-tree paper's subdivided bunny: `subdivide fixtures/bunny.obj --levels 1 -o
    /// bunny_loop.obj`).
    Subdivide(SubdivideArgs),
    /// Remesh any mesh into a semi-regular one for the wavelet engine: a simplification of it
    /// to about --base faces, subdivided --levels times, every vertex on the input surface
    /// through a bijective map of the base onto it; prints its distances to the input.
    Remesh(RemeshArgs),
    /// Run one of the papers' experiments: pictures and CSV into OUT/NAME/, one `key=value`
    /// summary line per engine or setting.
    Reproduce(ReproduceArgs),
}

#[derive(clap::Args)]
struct InfoArgs {
    /// The file.
    file: PathBuf,
    /// Also measure the file's full detail against this mesh (OBJ, OFF, PLY or STL; the one it
    /// was made from): two-sided Hausdorff and RMS distances as percentages of the mesh's
    /// bounding-box diagonal.
    #[arg(long, value_name = "MESH")]
    against: Option<PathBuf>,
    #[command(flatten)]
    input: InputArgs,
}

#[derive(clap::Args)]
struct SphereArgs {
    /// Subdivision levels.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=8))]
    levels: u32,
    /// Output file (.vdw).
    #[arg(long, short)]
    out: PathBuf,
    /// Also write the finest level as an OBJ file.
    #[arg(long)]
    obj: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum SchemeArg {
    /// Loop subdivision (smooth).
    Loop,
    /// Midpoint subdivision (flat: every wavelet coefficient is zero).
    Midpoint,
}

#[derive(clap::Args)]
struct RepairArgs {
    /// Mesh file (OBJ, OFF, PLY or STL).
    mesh: PathBuf,
    /// Output OBJ file.
    #[arg(long, short)]
    out: PathBuf,
    /// The mesh file's up axis.
    #[arg(long, value_enum, default_value = "y")]
    up: UpArg,
}

#[derive(clap::Args)]
struct SubdivideArgs {
    /// Mesh file (OBJ, OFF, PLY or STL).
    mesh: PathBuf,
    #[command(flatten)]
    input: InputArgs,
    /// Subdivision levels.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=8))]
    levels: u32,
    /// How the new vertices are placed.
    #[arg(long, value_enum, default_value = "loop")]
    scheme: SchemeArg,
    /// Simplify the mesh to about this many faces first (0: use it as it is).
    #[arg(long, default_value_t = 0)]
    base: u32,
    /// Output file: .vdw (semi-regular), or .obj (the subdivided mesh, Loop scheme, no base).
    #[arg(long, short)]
    out: PathBuf,
    /// Also write the finest level as an OBJ file.
    #[arg(long)]
    obj: Option<PathBuf>,
}

#[derive(clap::Args)]
struct RemeshArgs {
    /// Mesh file (OBJ, OFF, PLY or STL).
    mesh: PathBuf,
    #[command(flatten)]
    input: InputArgs,
    /// Faces of the base mesh to aim for.
    #[arg(long, default_value_t = 300)]
    base: u32,
    /// Subdivision levels.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=8))]
    levels: u32,
    /// Output file (.vdw).
    #[arg(long, short)]
    out: PathBuf,
    /// Also write the finest level as an OBJ file.
    #[arg(long)]
    obj: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum Experiment {
    /// The wavelet paper's fish experiment (Azuma et al. 2003, Fig. 13) on our meshes: the
    /// bunny and the cow remeshed to a ~200-face base and four levels; the adaptive mesh at
    /// 2 / 10 px against three uniform levels, flat and with a checker over the base faces;
    /// both engines at equal triangles, PSNR against the input.
    Fish,
    /// The wavelet paper (Azuma et al. 2003), Fig. 11: the 8,192-face sphere at 0.5 px
    /// silhouette / 3.5 px interior tolerance (paper: 732 faces), both engines.
    Fig11,
    /// The wavelet paper, Fig. 9 (and Fig. 13's face counts): a session that turns around the
    /// model, then zooms in, over the sphere and a 51,200-face subdivided mesh with a 200-face
    /// base; faces and milliseconds per frame.
    Fig9,
    /// The wavelet paper, Fig. 10: the spheroid against Hoppe's bound over the same session, both engines.
    Fig10,
    /// Both engines (wavelets, vertex forest) on the same meshes at equal triangle counts: PSNR,
    /// adaptation time, file and cut sizes.
    Engines,
    /// The merge-tree paper's Table 1: the Loop-subdivided bunny (301,632 triangles, hierarchy by
    /// shortest edge with balancing) refined inside a frustum moving on a level orbit and near
    /// the camera, at frustum sizes 0.4 / 0.2 / 0.1 (0.2 calibrated to hold 10% of the
    /// leaves): adapt + render against drawing every triangle (paper: 5x / 10x / 12.5x).
    Table1,
    /// The importance paper (Ng et al.), Figs. 3-10: a 20,000-triangle terrain reduced to 25%
    /// and 10% with its colour cost and with QEM, then refined with its importance test at its
    /// threshold of 0.3; the figure set and PSNR against full detail.
    Terrain,
    /// Both engines (wavelets, and the vertex forest built by default and on endpoints) on one
    /// 257 x 257 terrain's fly-over at equal triangle counts: PSNR, new triangles per frame,
    /// adaptation time, file and cut sizes.
    TerrainEngines,
    /// Both engines on a 1025 x 1025 terrain at Lindstrom et al.'s tolerances (0.5, 1, 2,
    /// 4 px): triangles and the share of pixels differing from full detail (takes about a
    /// minute and 500 MB).
    TerrainTolerances,
    /// The wavelet paper, §3.1: textures over the parametric domain. Both engines at equal
    /// triangles on the 257 x 257 terrain's fly-over, drawn with its colours as a texture, with a
    /// checker, and with colours per vertex: PSNR against full detail, and pictures.
    Textures,
}

#[derive(clap::Args)]
struct ReproduceArgs {
    /// The experiment.
    #[arg(value_enum)]
    name: Experiment,
    /// Parent directory of the experiment's folder.
    #[arg(long, short, default_value = "out")]
    out: PathBuf,
    /// Rounds of `table1`'s flights, flown in turn: each line then gives the medians over
    /// rounds and the range of the speed-up and of adaptation's share.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    rounds: u32,
}

#[derive(Clone, Copy, ValueEnum)]
enum CostArg {
    /// Quadric error metric with optimal placement.
    Qem,
    /// Shortest edge first (merge-tree paper).
    Edge,
    /// Colour-aware cost of the importance paper.
    Color,
}

#[derive(clap::Args)]
struct BuildArgs {
    /// Mesh file to build from (OBJ, OFF, PLY or STL).
    mesh: PathBuf,
    #[command(flatten)]
    input: InputArgs,
    /// Output file.
    #[arg(long, short)]
    out: PathBuf,
    /// Collapse cost.
    #[arg(long, value_enum, default_value = "qem")]
    cost: CostArg,
    /// Balance the forest with the merge-tree paper's region-of-influence marking.
    #[arg(long)]
    balanced: bool,
    /// Stop at this many base-mesh vertices (default: as few as topology allows).
    #[arg(long, default_value_t = 0)]
    base: u32,
    /// The error bound each vertex carries.
    #[arg(long, value_enum, default_value = "offset")]
    bound: BoundArg,
    /// Where a collapse puts the vertex it makes.
    #[arg(long, value_enum, default_value = "cost")]
    placement: PlacementArg,
}

#[derive(Clone, Copy, ValueEnum)]
enum BoundArg {
    /// The leaves' offsets along the vertex normal, as a sphere (widened across a border).
    Offset,
    /// The wavelet paper's spheroid (equation 3) over the leaves' distances to the coarse
    /// surface around the vertex.
    Spheroid,
    /// Hoppe's sphere swept along the normal over the same distances (flights then use his
    /// screen-space test).
    Hoppe,
}

impl From<BoundArg> for ErrorBound {
    fn from(b: BoundArg) -> ErrorBound {
        match b {
            BoundArg::Offset => ErrorBound::Offset,
            BoundArg::Spheroid => ErrorBound::Spheroid,
            BoundArg::Hoppe => ErrorBound::Hoppe,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum PlacementArg {
    /// Where the cost puts it: the quadrics' minimiser (qem), else the edge's midpoint.
    Cost,
    /// On one of the two endpoints, with its normal and colour (a half-edge collapse): fewer
    /// triangles change per frame, at some cost in fidelity.
    Endpoint,
}

impl From<PlacementArg> for Placement {
    fn from(p: PlacementArg) -> Placement {
        match p {
            PlacementArg::Cost => Placement::Cost,
            PlacementArg::Endpoint => Placement::Endpoint,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum PolicyArg {
    /// Frustum, back-face and screen-space error (--tolerance, --interior).
    Screen,
    /// The merge-tree paper's shouldRefine: everything in the frustum (--frustum) and near the
    /// eye (--near), to the leaves.
    MergeTree,
    /// The importance paper's triangle importance over --threshold.
    Importance,
}

/// How a flight adapts, draws and reports: shared by `orbit` and `terrain`.
#[derive(clap::Args)]
struct FlightArgs {
    /// Triangle budget: the cut never has more (at least 1).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    budget: Option<u32>,
    /// Regulate the tolerance towards this many triangles (at least 1).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    target: Option<u32>,
    /// Regulate the tolerance towards this frame time in milliseconds (adapt + render, as
    /// measured on this machine; with --target, the stricter one wins).
    #[arg(long, value_parser = positive)]
    target_ms: Option<f32>,
    /// Splits plus collapses per frame at most (at least 1).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    max_ops: Option<u32>,
    /// Active vertices asked per frame at most (at least 1): the traversal spread over frames,
    /// each frame going on where the last stopped (vertex forest only).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    max_visits: Option<u32>,
    /// Screen-space tolerance in pixels (at the silhouette, and inside unless --interior); 0
    /// asks for full detail.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true, value_parser = non_negative)]
    tolerance: f32,
    /// Screen-space tolerance in pixels inside the silhouette (0: full detail).
    #[arg(long, allow_negative_numbers = true, value_parser = non_negative)]
    interior: Option<f32>,
    /// Refinement policy.
    #[arg(long, value_enum, default_value = "screen")]
    policy: PolicyArg,
    /// Importance threshold (with --policy importance; in units of the model's size, see
    /// `Importance`; 0 refines everything visible).
    #[arg(long, default_value_t = Importance::DEFAULT_THRESHOLD, allow_negative_numbers = true, value_parser = non_negative)]
    threshold: f32,
    /// Frustum size: the refinement frustum's width and height relative to the camera's
    /// (the merge-tree paper's Table 1 uses 0.4, 0.2, 0.1; above 0).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true, value_parser = positive)]
    frustum: f32,
    /// With --policy merge-tree: refine only what comes within this distance of the eye, in
    /// radii of the model's bounding sphere (the merge-tree orbit's eye is 2 radii from the
    /// centre; default: no limit).
    #[arg(long, allow_negative_numbers = true, value_parser = positive)]
    near: Option<f32>,
    /// Frames in one revolution (with --path, the file's rows set the frames).
    #[arg(long, default_value_t = 72, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: u32,
    /// Frame width in pixels (1 to 4096).
    #[arg(long, default_value_t = 640, value_parser = dimension)]
    width: usize,
    /// Frame height in pixels (1 to 4096).
    #[arg(long, default_value_t = 480, value_parser = dimension)]
    height: usize,
    /// Geomorph length in frames (0: none).
    #[arg(long, default_value_t = 4)]
    geomorph: u16,
    /// False colour by forest depth.
    #[arg(long)]
    depth_colors: bool,
    /// Draw triangle edges.
    #[arg(long)]
    wireframe: bool,
    /// Also write each frame's active mesh as mesh_NNNN.obj.
    #[arg(long)]
    dump_mesh: bool,
    /// Draw the frames from an observer (on an orbit, a quarter turn ahead and a quarter farther
    /// away; on a path, from above), to see where the cut put its detail (the statistics still
    /// compare the flying camera's view).
    #[arg(long)]
    observer: bool,
    /// A camera path file to fly instead: CSV, one frame per line,
    /// eye_x,eye_y,eye_z,target_x,target_y,target_z,up_x,up_y,up_z,fov_y_degrees.
    #[arg(long, conflicts_with = "session")]
    path: Option<PathBuf>,
    /// Fly the wavelet paper's session instead: two thirds of the frames turning around the
    /// scene at three radii, the rest zooming in to a close-up of its surface.
    #[arg(long)]
    session: bool,
}

impl Default for FlightArgs {
    fn default() -> Self {
        FlightArgs {
            budget: None,
            target: None,
            target_ms: None,
            max_ops: None,
            max_visits: None,
            tolerance: 1.0,
            interior: None,
            policy: PolicyArg::Screen,
            threshold: 0.3,
            frustum: 1.0,
            near: None,
            frames: 72,
            width: 640,
            height: 480,
            geomorph: 4,
            depth_colors: false,
            wireframe: false,
            dump_mesh: false,
            observer: false,
            path: None,
            session: false,
        }
    }
}

impl FlightArgs {
    /// What clap cannot check: options that only mean something together.
    fn check(&self) -> Result<(), String> {
        if self.near.is_some() && !matches!(self.policy, PolicyArg::MergeTree) {
            return Err("--near needs --policy merge-tree".into());
        }
        Ok(())
    }

    /// The options of a flight, with `path`'s cameras when there is one.
    fn options(&self, path: Option<Vec<Camera>>, peer_orbit: bool) -> OrbitOptions {
        let mut budget = Budget::default();
        if let Some(b) = self.budget {
            budget.max_triangles = b;
        }
        if let Some(t) = self.target {
            budget.target_triangles = t;
        }
        if let Some(m) = self.max_ops {
            budget.max_ops = m;
        }
        if let Some(v) = self.max_visits {
            budget.max_visits = v;
        }
        if let Some(ms) = self.target_ms {
            // At least a microsecond (`as` saturates above `u32::MAX`).
            budget.target_frame_us = ((ms * 1e3).round() as u32).max(1);
        }
        OrbitOptions {
            width: self.width,
            height: self.height,
            frames: path.as_ref().map_or(self.frames, |p| p.len() as u32),
            frustum: self.frustum,
            policy: match self.policy {
                PolicyArg::Screen => PolicyChoice::Screen {
                    silhouette: self.tolerance,
                    interior: self.interior.unwrap_or(self.tolerance),
                },
                PolicyArg::MergeTree => PolicyChoice::MergeTree {
                    near: self.near.unwrap_or(f32::INFINITY),
                },
                PolicyArg::Importance => PolicyChoice::Importance {
                    threshold: self.threshold,
                },
            },
            budget,
            geomorph_frames: self.geomorph,
            depth_colors: self.depth_colors,
            wireframe: self.wireframe,
            dump_mesh: self.dump_mesh,
            write_frames: true,
            peer_orbit,
            observer: self.observer,
            ground: None,
            path,
        }
    }

    /// The cameras of `--path` or `--session` over a scene in `bounds`, if given.
    fn path(&self, bounds: &Bounds) -> Result<Option<Vec<Camera>>, String> {
        if self.session {
            let (c, r) = (bounds.center(), bounds.radius());
            return Ok(Some(wavelet::session(
                c,
                r,
                self.frames,
                self.width,
                self.height,
            )));
        }
        let Some(file) = &self.path else {
            return Ok(None);
        };
        let text = std::fs::read_to_string(file)
            .map_err(|e| format!("{}: cannot read: {e}", file.display()))?;
        path_cameras(&text, bounds, self.width, self.height)
            .map(Some)
            .map_err(|e| format!("{}: {e}", file.display()))
    }
}

#[derive(clap::Args)]
struct OrbitArgs {
    /// Mesh file (OBJ, OFF, PLY or STL; its hierarchy is built first), .vdh hierarchy, or .vdw
    /// semi-regular file (flown by the wavelet engine) (default: the bundled bunny).
    mesh: Option<PathBuf>,
    #[command(flatten)]
    input: InputArgs,
    /// Output directory.
    #[arg(long, short, default_value = "out")]
    out: PathBuf,
    /// Fly the peer orbit (20 degrees up) of ../shared/peers instead of the level one.
    #[arg(long)]
    peer_orbit: bool,
    #[command(flatten)]
    flight: FlightArgs,
}

impl Default for OrbitArgs {
    fn default() -> Self {
        OrbitArgs {
            mesh: None,
            input: InputArgs::default(),
            out: PathBuf::from("out"),
            peer_orbit: false,
            flight: FlightArgs::default(),
        }
    }
}

#[derive(clap::Args)]
struct TerrainArgs {
    /// Heightmap: a grey PNG, 8 or 16 bits, any size from 2 x 2 to 2049 x 2049 (default: a
    /// procedural island).
    #[arg(long)]
    heightmap: Option<PathBuf>,
    /// Colormap: a PNG of the heightmap's size.
    #[arg(long, requires = "heightmap")]
    colormap: Option<PathBuf>,
    /// Height of a white pixel, as a fraction of the heightmap's width (above 0, at most 10).
    #[arg(long, default_value_t = terrain::DEFAULT_VERTICAL_SCALE, allow_negative_numbers = true, value_parser = vertical_scale)]
    vertical_scale: f32,
    /// Samples per side of the procedural terrain (2 to 2049).
    #[arg(long, default_value_t = 257, value_parser = clap::value_parser!(u32).range(2..=2049), conflicts_with = "heightmap")]
    size: u32,
    /// Seed of the procedural terrain.
    #[arg(long, default_value_t = 1, conflicts_with = "heightmap")]
    seed: u32,
    /// Output directory.
    #[arg(long, short, default_value = "out/terrain")]
    out: PathBuf,
    /// The engine: the vertex forest, or the wavelet engine (a square terrain of 2^k + 1
    /// samples a side, taken as it is).
    #[arg(long, value_enum, default_value = "forest")]
    engine: EngineArg,
    /// The vertex forest's error bound (as `build --bound`).
    #[arg(long, value_enum, default_value = "offset")]
    bound: BoundArg,
    /// Where the vertex forest's collapses put their vertices (as `build --placement`).
    #[arg(long, value_enum, default_value = "cost")]
    placement: PlacementArg,
    /// Draw the colours as a texture over the ground (one texel per sample; the full-detail
    /// frames too), not as a colour per vertex: they keep their detail where the mesh is coarse.
    #[arg(long)]
    texture: bool,
    #[command(flatten)]
    flight: FlightArgs,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum EngineArg {
    /// The vertex forest: a hierarchy built by edge collapses.
    Forest,
    /// The wavelet engine: the grid's own subdivision connectivity.
    Wavelet,
}

#[derive(Clone, Copy, ValueEnum)]
enum ShadingArg {
    Flat,
    Gouraud,
    Unlit,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Mesh file (OBJ, OFF, PLY or STL) or .vdh hierarchy to render at full detail (default: the
    /// bundled Stanford bunny).
    mesh: Option<PathBuf>,
    #[command(flatten)]
    input: InputArgs,
    /// Directory for frame_NNNN.png.
    #[arg(long, short, default_value = "out")]
    out: PathBuf,
    /// Frames in one revolution.
    #[arg(long, default_value_t = 36, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: u32,
    /// Frame width in pixels (1 to 4096).
    #[arg(long, default_value_t = 640, value_parser = dimension)]
    width: usize,
    /// Frame height in pixels (1 to 4096).
    #[arg(long, default_value_t = 480, value_parser = dimension)]
    height: usize,
    /// Shading mode.
    #[arg(long, value_enum, default_value = "gouraud")]
    shading: ShadingArg,
    /// Draw triangle edges over the shaded frame.
    #[arg(long)]
    wireframe: bool,
}

impl Default for RenderArgs {
    fn default() -> Self {
        RenderArgs {
            mesh: None,
            input: InputArgs::default(),
            out: PathBuf::from("out"),
            frames: 36,
            width: 640,
            height: 480,
            shading: ShadingArg::Gouraud,
            wireframe: false,
        }
    }
}

/// Loads a mesh file (or the bundled bunny), saying what was repaired.
fn load(mesh: Option<&PathBuf>, input: InputArgs) -> Result<(String, IndexedMesh), String> {
    let Some(path) = mesh else {
        let bunny = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).map_err(|e| e.to_string())?;
        return Ok((BUNNY_NAME.to_string(), bunny));
    };
    let name = path.display().to_string();
    let loaded = mesh::load(path, &input.options()).map_err(|e| e.to_string())?;
    if let Some(repairs) = loaded.repairs.filter(|r| !r.is_empty()) {
        say!("{name}: {}: repaired: {repairs}", loaded.format);
    }
    Ok((name, loaded.mesh))
}

/// The first four bytes of a file (zeros when it is shorter or unreadable).
fn magic(path: &Path) -> [u8; 4] {
    use std::io::Read as _;
    let mut magic = [0u8; 4];
    let _ = std::fs::File::open(path).and_then(|mut f| f.read_exact(&mut magic));
    magic
}

/// Whether the file is a vdlod hierarchy (by its first bytes, whatever its name).
fn is_hierarchy(path: &Path) -> bool {
    magic(path) == vdlod_core::format::MAGIC
}

/// Whether the file is a vdlod semi-regular mesh (by its first bytes, whatever its name).
fn is_semi_regular(path: &Path) -> bool {
    magic(path) == vdlod_core::wavelet::format::MAGIC
}

/// The bytes and the finest level of a .vdw file.
fn load_semi_regular(path: &Path) -> Result<(String, Vec<u8>, IndexedMesh), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let s = SemiRegularView::parse(&bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut full = wavelet::finest_of(&s);
    full.reorder_for_locality();
    Ok((path.display().to_string(), bytes, full))
}

fn render(args: RenderArgs) -> Result<(), String> {
    let (name, mut mesh) = match args.mesh.as_ref() {
        Some(path) if is_hierarchy(path) => {
            let (name, _, full) = load_hierarchy(path)?;
            (name, full)
        }
        mesh => load(mesh, args.input)?,
    };
    mesh.reorder_for_locality();
    let opts = RenderOptions {
        width: args.width,
        height: args.height,
        frames: args.frames,
        shading: match args.shading {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Gouraud => Shading::Gouraud,
            ShadingArg::Unlit => Shading::Unlit,
        },
        wireframe: args.wireframe,
    };
    say!(
        "{name}: {} vertices, {} triangles; {} frames at {}x{} into {}",
        mesh.positions.len(),
        mesh.triangles.len(),
        opts.frames,
        opts.width,
        opts.height,
        args.out.display()
    );
    let reports = render_orbit(&mesh, &opts, &args.out, |r| {
        say!(
            "frame {:04}  triangles {:>7} of {:>7}  {:>8.3} ms",
            r.index,
            r.rasterized,
            r.submitted,
            r.ms
        )
    })
    .map_err(|e| format!("{}: {e}", args.out.display()))?;
    let mut ms: Vec<f64> = reports.iter().map(|r| r.ms).collect();
    ms.sort_by(f64::total_cmp);
    say!(
        "median {:.3} ms per frame over {} frames",
        ms[ms.len() / 2],
        ms.len()
    );
    Ok(())
}

/// The bytes and the full-detail mesh of a .vdh file.
fn load_hierarchy(path: &Path) -> Result<(String, Vec<u8>, IndexedMesh), String> {
    let bytes = hierarchy::read(path)?;
    let view = HierarchyView::parse(&bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    let full = lod::full_detail(&view).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok((path.display().to_string(), bytes, full))
}

/// The hierarchy bytes and the full-detail mesh of a mesh or .vdh argument.
fn load_lod(
    mesh: Option<&PathBuf>,
    input: InputArgs,
) -> Result<(String, Vec<u8>, IndexedMesh), String> {
    if let Some(path) = mesh.filter(|p| is_hierarchy(p)) {
        return load_hierarchy(path);
    }
    if let Some(path) = mesh.filter(|p| is_semi_regular(p)) {
        return load_semi_regular(path);
    }
    let (name, mut full) = load(mesh, input)?;
    let show = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let (_, bytes, seconds) = hierarchy::build_with_progress(&full, &BuildOptions::default(), show)
        .map_err(|e| format!("{name}: {e}"))?;
    say!("{name}: hierarchy built in {seconds:.2} s");
    full.reorder_for_locality();
    Ok((name, bytes, full))
}

fn orbit_command(args: OrbitArgs) -> Result<(), String> {
    args.flight.check()?;
    let (name, bytes, full) = load_lod(args.mesh.as_ref(), args.input)?;
    let path = args.flight.path(&full.bounds())?;
    let opts = args.flight.options(path, args.peer_orbit);
    fly(&name, &bytes, &full, &opts, &args.out)
}

fn terrain_command(args: TerrainArgs) -> Result<(), String> {
    args.flight.check()?;
    let (name, land) = match &args.heightmap {
        Some(file) => {
            let read = |p: &Path| {
                std::fs::read(p).map_err(|e| format!("{}: cannot read: {e}", p.display()))
            };
            let heights = read(file)?;
            let colors = args.colormap.as_deref().map(read).transpose()?;
            let land = Terrain::from_png(&heights, colors.as_deref(), args.vertical_scale)
                .map_err(|e| format!("{}: {e}", file.display()))?;
            (file.display().to_string(), land)
        }
        None => (
            format!(
                "procedural terrain (size {}, seed {})",
                args.size, args.seed
            ),
            Terrain::procedural(args.size as usize, args.seed, args.vertical_scale),
        ),
    };
    let mut full = land.mesh();
    let start = std::time::Instant::now();
    let bytes = match args.engine {
        EngineArg::Forest => {
            let show = std::io::IsTerminal::is_terminal(&std::io::stderr());
            let opts = BuildOptions {
                bound: args.bound.into(),
                placement: args.placement.into(),
                ..BuildOptions::default()
            };
            hierarchy::build_with_progress(&full, &opts, show)
                .map_err(|e| format!("{name}: {e}"))?
                .1
        }
        EngineArg::Wavelet => land
            .semi_regular()
            .ok_or_else(|| {
                format!(
                    "{name}: the wavelet engine needs a square terrain of 2^k + 1 samples a side \
                     (3, 5, 9, ..., 2049); this one is {} x {}",
                    land.width, land.depth
                )
            })?
            .to_height_bytes(terrain::UP_AXIS)
            .map_err(|e| format!("{name}: {e}"))?,
    };
    say!(
        "{name}: {} x {} samples, {} built in {:.2} s",
        land.width,
        land.depth,
        match args.engine {
            EngineArg::Forest => "hierarchy",
            EngineArg::Wavelet => "semi-regular mesh",
        },
        start.elapsed().as_secs_f64()
    );
    full.reorder_for_locality();
    let path = match args.flight.path(&full.bounds())? {
        Some(path) => path,
        None => {
            let f = &args.flight;
            let fly_over = FlyOver::new(&land, f.frames, f.width, f.height);
            (0..f.frames).map(|i| fly_over.camera(i)).collect()
        }
    };
    let mut opts = args.flight.options(Some(path), false);
    if args.texture {
        opts.ground = Some(
            vdlod_demo::ground::GroundTexture::of(&land)
                .ok_or_else(|| format!("{name}: --texture needs a colormap"))?,
        );
    }
    fly(&name, &bytes, &full, &opts, &args.out)
}

/// Flies `opts` over the hierarchy `bytes` of `full`, printing a line per frame and a summary.
fn fly(
    name: &str,
    bytes: &[u8],
    full: &IndexedMesh,
    opts: &OrbitOptions,
    out: &Path,
) -> Result<(), String> {
    say!(
        "{name}: {} vertices, {} triangles at full detail; {} frames at {}x{} into {}",
        full.positions.len(),
        full.triangles.len(),
        opts.frames,
        opts.width,
        opts.height,
        out.display()
    );
    let summary = lod::run_orbit(bytes, full, opts, out, |f| {
        let limits = lod::limits(&f.stats);
        say!(
                "frame {:04}  triangles {:>7}  splits {:>5}  collapses {:>5}  adapt {:>8.1} us  render {:>7.2} ms  full {:>7.2} ms  PSNR {:>6.2} dB{}{}",
                f.index,
                f.stats.triangles,
                f.stats.vsplits,
                f.stats.ecols,
                f.adapt_us,
                f.render_us / 1e3,
                f.full_render_us / 1e3,
                f.psnr_db,
                if limits.is_empty() { "" } else { "  limits: " },
                limits
            )
    })?;
    let first = summary.frames[0];
    say!(
        "first frame (from the base mesh): {} triangles, {} splits, {:.1} us",
        first.stats.triangles,
        first.stats.vsplits,
        first.adapt_us
    );
    if summary.frames.len() > 1 {
        say!(
            "other frames, median: adapt {:.1} us, {:.0} triangles ({:.1}% new), {:.1} splits + {:.1} collapses; adapt + render {:.2} ms vs full detail {:.2} ms; PSNR mean {:.2} dB",
            summary.median_after_first(|f| f.adapt_us),
            summary.median_after_first(|f| f.stats.triangles as f64),
            summary.median_after_first(|f| {
                100.0 * f.new_triangles as f64 / f.stats.triangles.max(1) as f64
            }),
            summary.mean_after_first(|f| f.stats.vsplits as f64),
            summary.mean_after_first(|f| f.stats.ecols as f64),
            summary.median_after_first(|f| (f.adapt_us + f.render_us) / 1e3),
            summary.median_after_first(|f| f.full_render_us / 1e3),
            summary.mean_after_first(|f| f.psnr_db.min(99.0)),
        );
    } else {
        say!("one frame only: no figures over the following frames");
    }
    if summary.hoppe_test {
        say!("the file has Hoppe's error bounds: tested as he does");
    }
    let counts = summary.limit_counts();
    if !counts.is_empty() {
        say!("limits hit (frames): {counts}; see the limit columns of stats.csv");
    }
    say!(
        "wrote {}/stats.csv, plot.png, side_by_side.png (frame {})",
        out.display(),
        summary.compared
    );
    Ok(())
}

fn build_command(args: BuildArgs) -> Result<(), String> {
    let (_, mesh) = load(Some(&args.mesh), args.input)?;
    let opts = BuildOptions {
        cost: match args.cost {
            CostArg::Qem => Cost::Quadric,
            CostArg::Edge => Cost::ShortestEdge,
            CostArg::Color => Cost::Color,
        },
        balanced: args.balanced,
        base_vertices: args.base,
        bound: args.bound.into(),
        placement: args.placement.into(),
    };
    let show = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let (_, bytes, seconds) = hierarchy::build_with_progress(&mesh, &opts, show)
        .map_err(|e| format!("{}: {e}", args.mesh.display()))?;
    // Validate, write beside the target, then rename: never an invalid or partial file.
    let view = HierarchyView::parse(&bytes).map_err(|e| format!("{}: {e}", args.out.display()))?;
    lod::full_detail(&view).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let mut partial = args.out.clone().into_os_string();
    partial.push(".partial");
    let partial = PathBuf::from(partial);
    std::fs::write(&partial, &bytes)
        .and_then(|()| std::fs::rename(&partial, &args.out))
        .map_err(|e| {
            let _ = std::fs::remove_file(&partial);
            format!("{}: cannot write: {e}", args.out.display())
        })?;
    say!("{}: {}", args.out.display(), hierarchy::summarize(&view));
    say!("built in {seconds:.3} s");
    Ok(())
}

fn repair(args: RepairArgs) -> Result<(), String> {
    let options = InputArgs {
        strict: false,
        up: args.up,
    }
    .options();
    let loaded = mesh::load(&args.mesh, &options).map_err(|e| e.to_string())?;
    let m = &loaded.mesh;
    say!(
        "{}: {}, {} vertices, {} triangles after repair: {}",
        args.mesh.display(),
        loaded.format,
        m.positions.len(),
        m.triangles.len(),
        loaded.repairs.unwrap_or_default()
    );
    let text = mesh::obj_text(
        &m.positions,
        m.colors.as_deref(),
        m.triangles.iter().copied(),
    );
    std::fs::write(&args.out, text)
        .map_err(|e| format!("{}: cannot write: {e}", args.out.display()))?;
    say!("wrote {}", args.out.display());
    Ok(())
}

fn info(args: InfoArgs) -> Result<(), String> {
    let file = &args.file;
    let raw = std::fs::read(file).map_err(|e| format!("{}: cannot read: {e}", file.display()))?;
    let full = if raw.starts_with(&vdlod_core::wavelet::format::MAGIC) {
        let s = SemiRegularView::parse(&raw).map_err(|e| format!("{}: {e}", file.display()))?;
        say!("{}: {}", file.display(), wavelet::summarize(&s));
        wavelet::finest_of(&s)
    } else {
        let bytes = hierarchy::read(file)?;
        let view = HierarchyView::parse(&bytes).map_err(|e| format!("{}: {e}", file.display()))?;
        // What `orbit` would reject, `info` rejects: refine it fully and check the mesh.
        let full = lod::full_detail(&view).map_err(|e| format!("{}: {e}", file.display()))?;
        say!("{}: {}", file.display(), hierarchy::summarize(&view));
        full
    };
    if let Some(against) = &args.against {
        let (name, mesh) = load(Some(against), args.input)?;
        let reference = vdlod_core::build::InputMesh {
            positions: &mesh.positions,
            colors: None,
            triangles: &mesh.triangles,
        };
        let d = vdlod_core::remesh::distances(&full.positions, &full.triangles, &reference);
        if d.samples == 0 {
            return Err(format!(
                "{name}: not a mesh the file can be measured against"
            ));
        }
        say!(
            "{}: full detail against {name}: hausdorff_pct={:.3} rms_pct={:.4} (of its bounding-box diagonal, {} samples both ways)",
            file.display(),
            100.0 * d.hausdorff,
            100.0 * d.rms,
            d.samples
        );
    }
    Ok(())
}

fn sphere(args: SphereArgs) -> Result<(), String> {
    let mesh = SemiRegular::sphere(args.levels).map_err(|e| e.to_string())?;
    write_semi_regular(&mesh, "sphere", &args.out, args.obj.as_deref())
}

/// Writes `mesh` (made from `source`) to `out`, and its finest level to `obj`, saying so.
fn write_semi_regular(
    mesh: &SemiRegular,
    source: &str,
    out: &Path,
    obj: Option<&Path>,
) -> Result<(), String> {
    let bytes = mesh.to_bytes().map_err(|e| format!("{source}: {e}"))?;
    let s = SemiRegularView::parse(&bytes).map_err(|e| format!("{}: {e}", out.display()))?;
    wavelet::write_file(out, &bytes)?;
    say!("{}: {}", out.display(), wavelet::summarize(&s));
    if let Some(obj) = obj {
        wavelet::write_obj(mesh, obj)?;
        say!("{}: the finest level as OBJ", obj.display());
    }
    Ok(())
}

fn subdivide(args: SubdivideArgs) -> Result<(), String> {
    let (_, mesh) = load(Some(&args.mesh), args.input)?;
    let plain = args
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    if plain {
        return subdivide_plain(&args, mesh);
    }
    let base = if args.base > 0 {
        wavelet::simplified_base(&mesh, args.base)
            .map_err(|e| format!("{}: {e}", args.mesh.display()))?
    } else {
        wavelet::BaseMesh {
            positions: mesh.positions.clone(),
            triangles: mesh.triangles.clone(),
        }
    };
    let scheme = match args.scheme {
        SchemeArg::Loop => Scheme::Loop,
        SchemeArg::Midpoint => Scheme::Midpoint,
    };
    let semi = SemiRegular::subdivide(&base.positions, &base.triangles, args.levels, scheme)
        .map_err(|e| format!("{}: {e}", args.mesh.display()))?;
    let source = args.mesh.display().to_string();
    write_semi_regular(&semi, &source, &args.out, args.obj.as_deref())
}

/// `subdivide` into an OBJ file: the whole mesh, Loop-subdivided `levels` times.
fn subdivide_plain(args: &SubdivideArgs, mut mesh: IndexedMesh) -> Result<(), String> {
    if args.base > 0 || args.obj.is_some() || !matches!(args.scheme, SchemeArg::Loop) {
        return Err(format!(
            "{}: an .obj output is the whole mesh Loop-subdivided: --base, --obj and --scheme are for .vdw outputs",
            args.out.display()
        ));
    }
    let bar = indicatif::ProgressBar::new(u64::from(args.levels));
    for _ in 0..args.levels {
        mesh = mesh.loop_subdivide();
        bar.inc(1);
    }
    bar.finish_and_clear();
    let text = mesh::obj_text(
        &mesh.positions,
        mesh.colors.as_deref(),
        mesh.triangles.iter().copied(),
    );
    std::fs::write(&args.out, text).map_err(|e| format!("{}: {e}", args.out.display()))?;
    say!(
        "{}: {} vertices, {} triangles ({} Loop subdivision steps of {})",
        args.out.display(),
        mesh.positions.len(),
        mesh.triangles.len(),
        args.levels,
        args.mesh.display()
    );
    Ok(())
}

fn remesh_command(args: RemeshArgs) -> Result<(), String> {
    let (source, mesh) = load(Some(&args.mesh), args.input)?;
    let options = vdlod_core::remesh::RemeshOptions {
        base_faces: args.base,
        levels: args.levels,
    };
    let done = vdlod_demo::remesh::remesh_with_progress(&mesh, &options, true)
        .map_err(|e| format!("{source}: {e}"))?;
    say!(
        "{source}: {}",
        vdlod_demo::remesh::summary(&done, args.levels)
    );
    write_semi_regular(&done.remesh.mesh, &source, &args.out, args.obj.as_deref())
}

fn reproduce(args: ReproduceArgs) -> Result<(), String> {
    if args.rounds != 1 && !matches!(args.name, Experiment::Table1) {
        return Err("--rounds applies to table1 only".into());
    }
    let (name, lines) = match args.name {
        Experiment::Fish => ("fish", wavelet::fish(&args.out.join("fish"))?),
        Experiment::Fig11 => ("fig11", wavelet::fig11(&args.out.join("fig11"))?),
        Experiment::Fig9 => ("fig9", wavelet::fig9(&args.out.join("fig9"))?),
        Experiment::Fig10 => ("fig10", wavelet::fig10(&args.out.join("fig10"))?),
        Experiment::Engines => ("engines", wavelet::engines(&args.out.join("engines"))?),
        Experiment::Table1 => (
            "table1",
            table1::table1(
                &args.out.join("table1"),
                load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).map_err(|e| e.to_string())?,
                table1::Setup {
                    rounds: args.rounds,
                    ..table1::Setup::REPRODUCE
                },
            )?,
        ),
        Experiment::Terrain => ("terrain", importance::terrain(&args.out.join("terrain"))?),
        Experiment::TerrainEngines => (
            "terrain-engines",
            terrain_engines::terrain_engines(
                &args.out.join("terrain-engines"),
                terrain_engines::Setup::REPRODUCE,
            )?,
        ),
        Experiment::TerrainTolerances => (
            "terrain-tolerances",
            terrain_engines::tolerances(&args.out.join("terrain-tolerances"), 1025, 36)?,
        ),
        Experiment::Textures => (
            "textures",
            textures::textures(&args.out.join("textures"), textures::REPRODUCE, 20)?,
        ),
    };
    for line in lines {
        say!("{line}");
    }
    say!("wrote {}", args.out.join(name).display());
    Ok(())
}

/// Writes one line to standard output. When the reader has gone (`vdlod-demo ... | head -1`)
/// the command ends there, successfully: nobody is listening. When the output cannot be written
/// (`> /dev/full`) it ends with one error line.
fn say(line: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(line).and_then(|()| out.write_all(b"\n")) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("vdlod-demo: error: standard output: {e}");
        std::process::exit(1);
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Orbit(args)) => orbit_command(args),
        Some(Command::Terrain(args)) => terrain_command(args),
        Some(Command::Render(args)) => render(args),
        Some(Command::Build(args)) => build_command(args),
        Some(Command::Repair(args)) => repair(args),
        Some(Command::Info(args)) => info(args),
        Some(Command::Sphere(args)) => sphere(args),
        Some(Command::Subdivide(args)) => subdivide(args),
        Some(Command::Remesh(args)) => remesh_command(args),
        Some(Command::Reproduce(args)) => reproduce(args),
        None => orbit_command(OrbitArgs::default()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("vdlod-demo: error: {msg}");
            ExitCode::FAILURE
        }
    }
}
