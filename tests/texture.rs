//! Textured drawing: perspective-correct coordinates (checked against rays through the pixel
//! centres), clipped triangles, bands, and a mesh without coordinates.

use glam::{Mat4, Vec3, Vec4};
use vdlod_raster::texture::{Filter, Texture, Wrap};
use vdlod_raster::{
    shade, DrawError, DrawParams, Mesh, Rgba8, ShadedVertex, Shading, Target, Window, DEPTH_CLEAR,
};

const W: usize = 96;
const H: usize = 64;
const BG: Rgba8 = Rgba8([7, 7, 7, 255]);

/// A floor `y = 0`, `x` in `-4..4`, `z` in `-8..2` (it reaches behind the camera, so the near
/// plane clips it), with `u = (x + 4) / 8` and `v = (2 - z) / 10`.
struct Floor {
    positions: [[f32; 3]; 4],
    uvs: [[f32; 2]; 4],
    triangles: [[u32; 3]; 2],
}

fn floor() -> Floor {
    let positions = [
        [-4.0, 0.0, 2.0],
        [4.0, 0.0, 2.0],
        [4.0, 0.0, -8.0],
        [-4.0, 0.0, -8.0],
    ];
    Floor {
        positions,
        uvs: positions.map(|p| [(p[0] + 4.0) / 8.0, (2.0 - p[2]) / 10.0]),
        triangles: [[0, 1, 2], [0, 2, 3]],
    }
}

fn mvp() -> Mat4 {
    Mat4::perspective_rh(1.0, W as f32 / H as f32, 0.3, 50.0)
        * Mat4::look_at_rh(Vec3::new(0.3, 0.6, 1.0), Vec3::new(0.0, 0.0, -3.0), Vec3::Y)
}

/// A 256 x 256 texture whose texel `(x, y)` is `(x, y, 0)`: a fragment's colour names the texel.
fn coordinates() -> Vec<Rgba8> {
    (0..256 * 256)
        .map(|i| Rgba8([(i % 256) as u8, (i / 256) as u8, 0, 255]))
        .collect()
}

/// Draws the floor into `W x H` through windows of `band` rows.
fn draw(band: usize) -> Vec<Rgba8> {
    let f = floor();
    let mesh = Mesh {
        positions: &f.positions,
        triangles: &f.triangles,
        uvs: Some(&f.uvs),
        ..Mesh::default()
    };
    let texels = coordinates();
    let texture = Texture::new(&texels, 256, 256, Filter::Nearest, Wrap::Clamp).unwrap();
    let params = DrawParams {
        mvp: mvp(),
        shading: Shading::Unlit,
        base_color: [255; 3],
        cull_back_faces: false,
        ..DrawParams::default()
    };
    let mut scratch = [ShadedVertex::default(); 4];
    let shaded = shade(&mesh, &params, W, H, &mut scratch).unwrap();
    let mut frame = vec![BG; W * H];
    for window in Window::bands(W, H, band) {
        let rows = window.height;
        let mut color = vec![BG; W * rows];
        let mut depth = vec![DEPTH_CLEAR; W * rows];
        let mut target = Target::window(&mut color, &mut depth, W, H, window, W).unwrap();
        let stats = shaded.draw_textured(&mut target, &texture).unwrap();
        assert!(stats.clipped > 0, "the near plane cuts the floor");
        frame[window.y * W..(window.y + rows) * W].copy_from_slice(&color);
    }
    frame
}

/// Where the ray through pixel `(x, y)`'s centre meets the floor, as `(u, v)`.
fn ray_uv(x: usize, y: usize) -> Option<[f32; 2]> {
    let inv = mvp().inverse();
    let ndc = |z: f32| {
        let nx = (x as f32 + 0.5) / W as f32 * 2.0 - 1.0;
        let ny = 1.0 - (y as f32 + 0.5) / H as f32 * 2.0;
        let p = inv * Vec4::new(nx, ny, z, 1.0);
        p.truncate() / p.w
    };
    let (a, b) = (ndc(0.0), ndc(1.0));
    let t = a.y / (a.y - b.y);
    let hit = a + (b - a) * t;
    (t > 0.0 && hit.x.abs() < 4.0 && hit.z > -8.0)
        .then(|| [(hit.x + 4.0) / 8.0, (2.0 - hit.z) / 10.0])
}

#[test]
fn texture_coordinates_follow_the_perspective() {
    let frame = draw(H);
    let (mut checked, mut worst, mut affine_far) = (0, 0.0f32, false);
    for y in 0..H {
        for x in 0..W {
            let px = frame[y * W + x];
            let Some(uv) = ray_uv(x, y) else { continue };
            if px == BG {
                continue;
            }
            // The texel the fragment shows against the texel the ray hits (clamped like the
            // texture), one texel of slack for rounding at texel borders.
            let expected = uv.map(|c| (c * 256.0).floor().clamp(0.0, 255.0));
            let err = (px.0[0] as f32 - expected[0])
                .abs()
                .max((px.0[1] as f32 - expected[1]).abs());
            worst = worst.max(err);
            checked += 1;
            // Half-way down the floor's image the affine value would be far from the true one.
            affine_far |= y == H * 3 / 4 && (expected[1] - 128.0).abs() > 20.0;
        }
    }
    assert!(checked > W * H / 3, "{checked} pixels");
    assert!(worst <= 1.0, "a fragment is {worst} texels off");
    assert!(
        affine_far,
        "the view is not steep enough to tell perspective from affine"
    );
}

#[test]
fn bands_draw_what_the_whole_frame_draws() {
    let whole = draw(H);
    assert_eq!(draw(16), whole);
    assert_eq!(draw(7), whole);
}

#[test]
fn a_mesh_without_coordinates_is_refused() {
    let f = floor();
    let mesh = Mesh {
        positions: &f.positions,
        triangles: &f.triangles,
        ..Mesh::default()
    };
    let texels = [Rgba8::default()];
    let texture = Texture::new(&texels, 1, 1, Filter::Bilinear, Wrap::Repeat).unwrap();
    let params = DrawParams {
        mvp: mvp(),
        shading: Shading::Unlit,
        ..DrawParams::default()
    };
    let mut scratch = [ShadedVertex::default(); 4];
    let shaded = shade(&mesh, &params, W, H, &mut scratch).unwrap();
    let (mut color, mut depth) = (vec![BG; W * H], vec![DEPTH_CLEAR; W * H]);
    let mut target = Target::new(&mut color, &mut depth, W, H).unwrap();
    assert_eq!(
        shaded.draw_textured(&mut target, &texture).unwrap_err(),
        DrawError::MissingUvs
    );
    let bad = Mesh {
        uvs: Some(&[[0.0; 2]; 3]),
        ..mesh
    };
    assert_eq!(
        shade(&bad, &params, W, H, &mut scratch).unwrap_err(),
        DrawError::AttributeLength {
            attribute: "uvs",
            expected: 4,
            actual: 3
        }
    );
}
