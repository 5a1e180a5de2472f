//! `vdlod-demo`: renders meshes with the vdlod rasterizer and writes PNG frames.
//!
//! With no arguments it renders the bundled Stanford bunny around the merge-tree paper's orbit
//! into `./out/`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Render(args)) => render(args),
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
