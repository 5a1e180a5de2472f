//! `vdlod-demo`: renders meshes with the vdlod rasterizer and writes PNG frames.
//!
//! With no arguments it renders the bundled Stanford bunny around the merge-tree paper's orbit
//! into `./out/`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use vdlod_core::build::{BuildOptions, Cost};
use vdlod_core::format::HierarchyView;
use vdlod_demo::hierarchy;
use vdlod_demo::mesh::{load_obj, load_obj_bytes, IndexedMesh, MeshError, BUNNY_NAME, BUNNY_OBJ};
use vdlod_demo::render::{render_orbit, RenderOptions};
use vdlod_raster::Shading;

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
    /// Fly the merge-tree paper's orbit around a mesh at full detail and write PNG frames.
    Render(RenderArgs),
    /// Build a mesh's vertex hierarchy and write it as a .vdh file.
    Build(BuildArgs),
    /// Validate a .vdh file and print its figures.
    Info {
        /// The hierarchy file.
        file: PathBuf,
    },
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
    /// OBJ file to build from.
    mesh: PathBuf,
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
}

#[derive(Clone, Copy, ValueEnum)]
enum ShadingArg {
    Flat,
    Gouraud,
    Unlit,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// OBJ file to render (default: the bundled Stanford bunny).
    mesh: Option<PathBuf>,
    /// Directory for frame_NNNN.png.
    #[arg(long, short, default_value = "out")]
    out: PathBuf,
    /// Frames in one revolution.
    #[arg(long, default_value_t = 36, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: u32,
    /// Frame width in pixels.
    #[arg(long, default_value_t = 640)]
    width: usize,
    /// Frame height in pixels.
    #[arg(long, default_value_t = 480)]
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
            out: PathBuf::from("out"),
            frames: 36,
            width: 640,
            height: 480,
            shading: ShadingArg::Gouraud,
            wireframe: false,
        }
    }
}

fn load(mesh: Option<&PathBuf>) -> Result<(String, IndexedMesh), MeshError> {
    match mesh {
        Some(path) => Ok((path.display().to_string(), load_obj(path)?)),
        None => Ok((
            BUNNY_NAME.to_string(),
            load_obj_bytes(BUNNY_NAME, BUNNY_OBJ)?,
        )),
    }
}

fn render(args: RenderArgs) -> Result<(), String> {
    let (name, mut mesh) = load(args.mesh.as_ref()).map_err(|e| e.to_string())?;
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
    println!(
        "{name}: {} vertices, {} triangles; {} frames at {}x{} into {}",
        mesh.positions.len(),
        mesh.triangles.len(),
        opts.frames,
        opts.width,
        opts.height,
        args.out.display()
    );
    let reports = render_orbit(&mesh, &opts, &args.out, |r| {
        println!(
            "frame {:04}  triangles {:>7} of {:>7}  {:>8.3} ms",
            r.index, r.rasterized, r.submitted, r.ms
        )
    })
    .map_err(|e| format!("{}: {e}", args.out.display()))?;
    let mut ms: Vec<f64> = reports.iter().map(|r| r.ms).collect();
    ms.sort_by(f64::total_cmp);
    println!(
        "median {:.3} ms per frame over {} frames",
        ms[ms.len() / 2],
        ms.len()
    );
    Ok(())
}

fn build_command(args: BuildArgs) -> Result<(), String> {
    let mesh = load_obj(&args.mesh).map_err(|e| e.to_string())?;
    let opts = BuildOptions {
        cost: match args.cost {
            CostArg::Qem => Cost::Quadric,
            CostArg::Edge => Cost::ShortestEdge,
            CostArg::Color => Cost::Color,
        },
        balanced: args.balanced,
        base_vertices: args.base,
    };
    let show = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let (_, bytes, seconds) = hierarchy::build_with_progress(&mesh, &opts, show)
        .map_err(|e| format!("{}: {e}", args.mesh.display()))?;
    std::fs::write(&args.out, &bytes)
        .map_err(|e| format!("{}: cannot write: {e}", args.out.display()))?;
    let view = HierarchyView::parse(&bytes).map_err(|e| format!("{}: {e}", args.out.display()))?;
    println!("{}: {}", args.out.display(), hierarchy::summarize(&view));
    println!("built in {seconds:.3} s");
    Ok(())
}

fn info(file: PathBuf) -> Result<(), String> {
    let bytes = hierarchy::read(&file)?;
    let view = HierarchyView::parse(&bytes).map_err(|e| format!("{}: {e}", file.display()))?;
    println!("{}: {}", file.display(), hierarchy::summarize(&view));
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Render(args)) => render(args),
        Some(Command::Build(args)) => build_command(args),
        Some(Command::Info { file }) => info(file),
        None => render(RenderArgs::default()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("vdlod-demo: error: {msg}");
            ExitCode::FAILURE
        }
    }
}
