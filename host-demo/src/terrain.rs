//! Terrains: a heightmap (and a colormap) from PNG files, or a procedural default, as a grid
//! mesh; and the low fly-over the `terrain` command flies over it.
//!
//! Sample `(column, row)` becomes the vertex `(column, height, row)`: one unit between samples,
//! +Y up. Each grid cell is two triangles, counter-clockwise seen from above. Heights are a
//! fraction of the grid's width: with a vertical scale `s`, a white pixel stands `s * (width - 1)`
//! units high, so the same file looks the same at any resolution.
//!
//! Everything here is deterministic: the procedural terrain is integer hashing and IEEE
//! arithmetic, no `std` float intrinsics.

use std::fmt;

use glam::Vec3;

use vdlod_core::wavelet::build::SemiRegular;

use crate::camera::Camera;
use crate::mesh::{vertex_normals, IndexedMesh};

/// Samples a terrain may have at most (2049 x 2049): the hierarchy builder needs about 1.2 KB of
/// memory per sample.
pub const MAX_SAMPLES: usize = 2049 * 2049;

/// The default vertical scale: a white pixel stands a tenth of the width high.
pub const DEFAULT_VERTICAL_SCALE: f32 = 0.1;

/// The coordinate axis heights stand along (`y`): what a terrain's semi-regular file is a height
/// field over ([`vdlod_core::wavelet::SemiRegular::to_height_bytes`]).
pub const UP_AXIS: usize = 1;

/// A height field with optional colours, row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct Terrain {
    /// Samples per row.
    pub width: usize,
    /// Rows.
    pub depth: usize,
    /// Heights, `width * depth`, row after row.
    pub heights: Vec<f32>,
    /// Colours, when there is a colormap.
    pub colors: Option<Vec<[u8; 3]>>,
}

/// Which image a [`TerrainError`] is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Image {
    /// The heightmap.
    Heightmap,
    /// The colormap.
    Colormap,
}

impl fmt::Display for Image {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Image::Heightmap => "heightmap",
            Image::Colormap => "colormap",
        })
    }
}

/// Why a terrain cannot be made.
#[derive(Clone, Debug, PartialEq)]
pub enum TerrainError {
    /// The PNG decoder refused the image.
    Png {
        /// Which image.
        image: Image,
        /// The decoder's message.
        message: String,
    },
    /// The heightmap has colours in it.
    NotGrey,
    /// Fewer than 2 x 2 samples.
    TooSmall {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// More than [`MAX_SAMPLES`] samples.
    TooLarge {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// The colormap's size differs from the heightmap's.
    SizeMismatch {
        /// The heightmap's size.
        heightmap: (usize, usize),
        /// The colormap's size.
        colormap: (usize, usize),
    },
    /// The vertical scale is not a finite number in (0, 10].
    Scale(f32),
}

impl fmt::Display for TerrainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TerrainError::Png { image, message } => write!(f, "{image}: not a PNG we read: {message}"),
            TerrainError::NotGrey => write!(
                f,
                "heightmap: not grey (an RGB pixel whose channels differ); save it as greyscale"
            ),
            TerrainError::TooSmall { width, height } => {
                write!(f, "heightmap: {width} x {height} pixels; at least 2 x 2 are needed")
            }
            TerrainError::TooLarge { width, height } => write!(
                f,
                "heightmap: {width} x {height} pixels is more than {MAX_SAMPLES} samples (2049 x 2049); downsample it"
            ),
            TerrainError::SizeMismatch {
                heightmap,
                colormap,
            } => write!(
                f,
                "colormap: {} x {} pixels, but the heightmap is {} x {}",
                colormap.0, colormap.1, heightmap.0, heightmap.1
            ),
            TerrainError::Scale(s) => {
                write!(f, "vertical scale {s}: must be a finite number above 0 and at most 10")
            }
        }
    }
}

impl std::error::Error for TerrainError {}

/// A decoded image: size, channels per pixel and samples scaled to 0..=65535.
struct Decoded {
    width: usize,
    height: usize,
    channels: usize,
    samples: Vec<u16>,
}

fn decode(bytes: &[u8], image: Image) -> Result<Decoded, TerrainError> {
    let err = |e: png::DecodingError| TerrainError::Png {
        image,
        message: e.to_string(),
    };
    // The decoder refuses images whose pixels would take more than this.
    let limits = png::Limits {
        bytes: MAX_SAMPLES * 8,
    };
    let mut decoder = png::Decoder::new_with_limits(std::io::Cursor::new(bytes), limits);
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(err)?;
    let (width, height) = {
        let info = reader.info();
        (info.width as usize, info.height as usize)
    };
    if width.saturating_mul(height) > MAX_SAMPLES {
        return Err(TerrainError::TooLarge { width, height });
    }
    let mut buffer = vec![0u8; reader.output_buffer_size()];
    let out = reader.next_frame(&mut buffer).map_err(err)?;
    let channels = out.color_type.samples();
    let wide = out.bit_depth == png::BitDepth::Sixteen;
    let row_samples = width * channels;
    let mut samples = Vec::with_capacity(row_samples * height);
    for row in buffer.chunks(out.line_size).take(height) {
        if wide {
            samples.extend(
                row.chunks_exact(2)
                    .take(row_samples)
                    .map(|b| u16::from_be_bytes([b[0], b[1]])),
            );
        } else {
            samples.extend(row.iter().take(row_samples).map(|&b| b as u16 * 257));
        }
    }
    Ok(Decoded {
        width,
        height,
        channels,
        samples,
    })
}

impl Terrain {
    /// A terrain from a grey heightmap PNG (8 or 16 bits; RGB accepted when every pixel is grey)
    /// and an optional colormap PNG of the same size.
    pub fn from_png(
        heightmap: &[u8],
        colormap: Option<&[u8]>,
        vertical_scale: f32,
    ) -> Result<Terrain, TerrainError> {
        if !(vertical_scale.is_finite() && vertical_scale > 0.0 && vertical_scale <= 10.0) {
            return Err(TerrainError::Scale(vertical_scale));
        }
        let h = decode(heightmap, Image::Heightmap)?;
        if h.width < 2 || h.height < 2 {
            return Err(TerrainError::TooSmall {
                width: h.width,
                height: h.height,
            });
        }
        // Grey, grey + alpha, RGB or RGBA: the first channel, if the colour ones agree.
        let colored = h.channels >= 3;
        let mut heights = Vec::with_capacity(h.width * h.height);
        let top = vertical_scale * (h.width - 1) as f32;
        for pixel in h.samples.chunks_exact(h.channels) {
            if colored && (pixel[0] != pixel[1] || pixel[1] != pixel[2]) {
                return Err(TerrainError::NotGrey);
            }
            heights.push(pixel[0] as f32 / 65535.0 * top);
        }
        let colors = match colormap {
            None => None,
            Some(bytes) => {
                let c = decode(bytes, Image::Colormap)?;
                if (c.width, c.height) != (h.width, h.height) {
                    return Err(TerrainError::SizeMismatch {
                        heightmap: (h.width, h.height),
                        colormap: (c.width, c.height),
                    });
                }
                let byte = |v: u16| (v >> 8) as u8;
                Some(
                    c.samples
                        .chunks_exact(c.channels)
                        .map(|p| match p.len() {
                            1 | 2 => [byte(p[0]); 3],
                            _ => [byte(p[0]), byte(p[1]), byte(p[2])],
                        })
                        .collect(),
                )
            }
        };
        Ok(Terrain {
            width: h.width,
            depth: h.height,
            heights,
            colors,
        })
    }

    /// The procedural default: an island of fractal value noise, `size` x `size` samples, its
    /// highest point `vertical_scale * (size - 1)` above the sea, with a colormap by height and
    /// slope (water, sand, grass, rock, snow). The same arguments give the same terrain on every
    /// machine.
    ///
    /// ```
    /// use vdlod_demo::terrain::{Terrain, DEFAULT_VERTICAL_SCALE};
    /// let t = Terrain::procedural(65, 7, DEFAULT_VERTICAL_SCALE);
    /// assert_eq!(t.heights.len(), 65 * 65);
    /// assert_eq!(t, Terrain::procedural(65, 7, DEFAULT_VERTICAL_SCALE));
    /// ```
    pub fn procedural(size: usize, seed: u32, vertical_scale: f32) -> Terrain {
        let size = size.max(2);
        let extent = (size - 1) as f32;
        let mut heights = Vec::with_capacity(size * size);
        for row in 0..size {
            for column in 0..size {
                let (u, v) = (column as f32 / extent, row as f32 / extent);
                let mut sum = 0.0;
                let mut amplitude = 0.5;
                let mut frequency = 4.0;
                for octave in 0..7 {
                    sum += amplitude * value_noise(u * frequency, v * frequency, seed ^ octave);
                    amplitude *= 0.5;
                    frequency *= 2.0;
                }
                // An island: lower towards the borders.
                let (du, dv) = (u - 0.5, v - 0.5);
                let falloff = 1.0 - 2.2 * (du * du + dv * dv);
                heights.push(sum * falloff);
            }
        }
        // Sea level at 35% of the range: water is flat.
        let lo = heights.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = heights.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let span = (hi - lo).max(f32::MIN_POSITIVE);
        let sea = 0.35;
        let top = vertical_scale * extent;
        let levels: Vec<f32> = heights.iter().map(|h| ((h - lo) / span).max(sea)).collect();
        let heights: Vec<f32> = levels
            .iter()
            .map(|t| (t - sea) / (1.0 - sea) * top)
            .collect();
        let colors = (0..size * size)
            .map(|i| {
                let (row, column) = (i / size, i % size);
                let at = |c: usize, r: usize| heights[r.min(size - 1) * size + c.min(size - 1)];
                let slope = (at(column + 1, row) - at(column.saturating_sub(1), row)).abs()
                    + (at(column, row + 1) - at(column, row.saturating_sub(1))).abs();
                biome((levels[i] - sea) / (1.0 - sea), slope * 0.5)
            })
            .collect();
        Terrain {
            width: size,
            depth: size,
            heights,
            colors: Some(colors),
        }
    }

    /// The grid as a triangle mesh: `width * depth` vertices, `2 (width - 1) (depth - 1)`
    /// triangles.
    pub fn mesh(&self) -> IndexedMesh {
        let (w, d) = (self.width, self.depth);
        let positions: Vec<[f32; 3]> = (0..w * d)
            .map(|i| [(i % w) as f32, self.heights[i], (i / w) as f32])
            .collect();
        let mut triangles = Vec::with_capacity(2 * (w - 1) * (d - 1));
        for row in 0..d - 1 {
            for column in 0..w - 1 {
                let a = (row * w + column) as u32;
                let (b, c) = (a + 1, a + w as u32);
                triangles.push([a, c, b]);
                triangles.push([b, c, c + 1]);
            }
        }
        let normals = vertex_normals(&positions, &triangles);
        IndexedMesh {
            positions,
            normals,
            colors: self.colors.clone(),
            triangles,
        }
    }

    /// The grid as a semi-regular mesh for the wavelet engine, when it is square with `2^k + 1`
    /// samples a side (`k` from 1 to 12, so 3 x 3 to 4097 x 4097): two base triangles split along the same diagonal as
    /// [`Terrain::mesh`]'s cells, subdivided `k` times, every vertex a sample (with its colour).
    /// `None` for any other size.
    ///
    /// ```
    /// use vdlod_demo::terrain::{Terrain, DEFAULT_VERTICAL_SCALE};
    /// let t = Terrain::procedural(17, 7, DEFAULT_VERTICAL_SCALE);
    /// let s = t.semi_regular().unwrap();
    /// assert_eq!(s.positions.len(), 17 * 17);
    /// assert_eq!(s.finest_triangles().len(), t.mesh().triangles.len());
    /// assert!(Terrain::procedural(18, 7, DEFAULT_VERTICAL_SCALE).semi_regular().is_none());
    /// ```
    pub fn semi_regular(&self) -> Option<SemiRegular> {
        let n = self.width - 1;
        let levels = n.trailing_zeros();
        if self.depth != self.width || !n.is_power_of_two() || !(1..=12).contains(&levels) {
            return None;
        }
        let corners = [(0, 0), (n, 0), (0, n), (n, n)];
        let at = |(c, r): (usize, usize)| [c as f32, self.heights[r * self.width + c], r as f32];
        let base = corners.map(at);
        let faces = [[0u32, 2, 1], [1, 2, 3]];
        let mut samples: Vec<usize> = corners.iter().map(|&(c, r)| r * self.width + c).collect();
        let mut mesh = SemiRegular::from_fn(&base, &faces, levels, |f, w| {
            // Weights are in units of 1 / 2^levels = 1 / n of the base triangle.
            let face = faces[f as usize].map(|v| corners[v as usize]);
            let (mut c, mut r) = (0, 0);
            for k in 0..3 {
                c += w[k].max(0) as usize * face[k].0 / n;
                r += w[k].max(0) as usize * face[k].1 / n;
            }
            samples.push(r * self.width + c);
            at((c, r))
        })
        .ok()?;
        mesh.colors = self
            .colors
            .as_ref()
            .map(|colors| samples.iter().map(|&i| colors[i]).collect());
        Some(mesh)
    }

    /// The height at `(x, z)`, bilinear between samples, clamped to the grid.
    pub fn height_at(&self, x: f32, z: f32) -> f32 {
        let (w, d) = (self.width, self.depth);
        let x = x.clamp(0.0, (w - 1) as f32);
        let z = z.clamp(0.0, (d - 1) as f32);
        let (c, r) = ((x as usize).min(w - 2), (z as usize).min(d - 2));
        let (fx, fz) = (x - c as f32, z - r as f32);
        let h = |c: usize, r: usize| self.heights[r * w + c];
        let near = h(c, r) + (h(c + 1, r) - h(c, r)) * fx;
        let far = h(c, r + 1) + (h(c + 1, r + 1) - h(c, r + 1)) * fx;
        near + (far - near) * fz
    }
}

/// The colour of a point at relative height `t` (0 at sea level, 1 at the top) and `slope`
/// (height change per sample).
fn biome(t: f32, slope: f32) -> [u8; 3] {
    if t <= 0.0 {
        [38, 84, 150] // water
    } else if t < 0.04 {
        [214, 196, 140] // sand
    } else if slope > 0.9 || (t > 0.55 && t < 0.75) {
        [120, 110, 100] // rock
    } else if t >= 0.75 {
        [240, 242, 246] // snow
    } else {
        [70, 130 - (t * 60.0) as u8, 60] // grass, darker higher up
    }
}

/// A hash of a lattice point to [0, 1).
fn lattice(x: i32, z: i32, seed: u32) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343)
        ^ (z as u32).wrapping_mul(0xd816_3841)
        ^ seed.wrapping_mul(0xcb1a_b31f);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297a_2d39);
    h ^= h >> 15;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Smooth value noise: lattice values blended with a smoothstep.
fn value_noise(x: f32, z: f32, seed: u32) -> f32 {
    let (xi, zi) = (libm::floorf(x), libm::floorf(z));
    let (fx, fz) = (x - xi, z - zi);
    let (sx, sz) = (fx * fx * (3.0 - 2.0 * fx), fz * fz * (3.0 - 2.0 * fz));
    let (xi, zi) = (xi as i32, zi as i32);
    let a = lattice(xi, zi, seed);
    let b = lattice(xi + 1, zi, seed);
    let c = lattice(xi, zi + 1, seed);
    let d = lattice(xi + 1, zi + 1, seed);
    let near = a + (b - a) * sx;
    let far = c + (d - c) * sx;
    near + (far - near) * sz
}

/// A low flight around a terrain: a loop at 30% of the grid's size from its centre, the eye a
/// little above the highest ground it will pass over next, looking ahead and slightly down.
#[derive(Clone, Debug)]
pub struct FlyOver {
    center: Vec3,
    radius: f32,
    extent: f32,
    clearance: f32,
    frames: u32,
    width: usize,
    height: usize,
    ground: Vec<f32>,
}

impl FlyOver {
    /// The fly-over of `terrain` in `frames` frames of `width` x `height` pixels.
    pub fn new(terrain: &Terrain, frames: u32, width: usize, height: usize) -> FlyOver {
        let frames = frames.max(1);
        let extent = (terrain.width.max(terrain.depth) - 1) as f32;
        let center = Vec3::new(
            (terrain.width - 1) as f32 * 0.5,
            0.0,
            (terrain.depth - 1) as f32 * 0.5,
        );
        let radius = 0.3 * extent;
        // The ground under the loop, sampled finely, so the eye never dips into a hill.
        let samples = 720;
        let ground = (0..samples)
            .map(|k| {
                let a = 2.0 * std::f32::consts::PI * k as f32 / samples as f32;
                terrain.height_at(
                    center.x + radius * libm::cosf(a),
                    center.z + radius * libm::sinf(a),
                )
            })
            .collect();
        FlyOver {
            center,
            radius,
            extent,
            clearance: 0.04 * extent,
            frames,
            width,
            height,
            ground,
        }
    }

    fn point(&self, angle: f32) -> Vec3 {
        let k = self.ground.len();
        let turn = angle / (2.0 * std::f32::consts::PI);
        let index = (libm::floorf(turn * k as f32) as i64).rem_euclid(k as i64) as usize;
        // The highest ground over the next tenth of a turn.
        let ahead = (0..k / 10)
            .map(|j| self.ground[(index + j) % k])
            .fold(f32::MIN, f32::max);
        Vec3::new(
            self.center.x + self.radius * libm::cosf(angle),
            ahead + self.clearance,
            self.center.z + self.radius * libm::sinf(angle),
        )
    }

    /// The camera of frame `i`.
    pub fn camera(&self, i: u32) -> Camera {
        let step = 2.0 * std::f32::consts::PI / self.frames as f32;
        let angle = step * (i % self.frames) as f32;
        let eye = self.point(angle);
        let ahead = self.point(angle + 0.35);
        let target = Vec3::new(ahead.x, ahead.y - self.clearance * 1.5, ahead.z);
        Camera {
            eye,
            target,
            up: Vec3::Y,
            fov_y: 60f32.to_radians(),
            near: self.extent * 0.002,
            far: self.extent * 1.6,
            width: self.width,
            height: self.height,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(
        width: u32,
        height: u32,
        color: png::ColorType,
        depth: png::BitDepth,
        data: &[u8],
    ) -> Vec<u8> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(color);
        encoder.set_depth(depth);
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(data).unwrap();
        drop(writer);
        out
    }

    #[test]
    fn grey_heightmaps_of_8_and_16_bits_agree() {
        let eight = png(
            3,
            2,
            png::ColorType::Grayscale,
            png::BitDepth::Eight,
            &[0, 255, 0, 0, 0, 255],
        );
        let wide: Vec<u8> = [0u16, 65535, 0, 0, 0, 65535]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        let sixteen = png(
            3,
            2,
            png::ColorType::Grayscale,
            png::BitDepth::Sixteen,
            &wide,
        );
        let a = Terrain::from_png(&eight, None, 0.5).unwrap();
        let b = Terrain::from_png(&sixteen, None, 0.5).unwrap();
        assert_eq!(a, b);
        // White stands half the width (2 units) high.
        assert_eq!(a.heights, vec![0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
        let mesh = a.mesh();
        assert_eq!(mesh.triangles.len(), 4);
        // Counter-clockwise from above: every normal points up.
        assert!(mesh.normals.iter().all(|n| n[1] > 0.0));
    }

    #[test]
    fn bad_images_are_typed_errors() {
        let rgb = png(
            2,
            2,
            png::ColorType::Rgb,
            png::BitDepth::Eight,
            &[9, 9, 9, 1, 2, 3, 0, 0, 0, 5, 5, 5],
        );
        assert_eq!(
            Terrain::from_png(&rgb, None, 0.1),
            Err(TerrainError::NotGrey)
        );
        let dot = png(1, 1, png::ColorType::Grayscale, png::BitDepth::Eight, &[0]);
        assert_eq!(
            Terrain::from_png(&dot, None, 0.1),
            Err(TerrainError::TooSmall {
                width: 1,
                height: 1
            })
        );
        let grey = png(
            2,
            2,
            png::ColorType::Grayscale,
            png::BitDepth::Eight,
            &[0; 4],
        );
        let colors = png(3, 2, png::ColorType::Rgb, png::BitDepth::Eight, &[0; 18]);
        assert!(matches!(
            Terrain::from_png(&grey, Some(&colors), 0.1),
            Err(TerrainError::SizeMismatch { .. })
        ));
        assert!(matches!(
            Terrain::from_png(&grey, None, f32::NAN),
            Err(TerrainError::Scale(s)) if s.is_nan()
        ));
        assert_eq!(
            Terrain::from_png(&grey, None, 11.0),
            Err(TerrainError::Scale(11.0))
        );
        assert!(matches!(
            Terrain::from_png(b"not a png", None, 0.1),
            Err(TerrainError::Png {
                image: Image::Heightmap,
                ..
            })
        ));
        let grey_rgb = png(2, 2, png::ColorType::Rgb, png::BitDepth::Eight, &[7; 12]);
        assert!(Terrain::from_png(&grey_rgb, Some(&colors[..]), 0.1).is_err());
        assert!(Terrain::from_png(&grey_rgb, None, 0.1).is_ok());
    }

    #[test]
    fn the_fly_over_stays_above_the_ground() {
        let t = Terrain::procedural(129, 3, DEFAULT_VERTICAL_SCALE);
        let path = FlyOver::new(&t, 90, 64, 48);
        for i in 0..90 {
            let c = path.camera(i);
            assert!(c.eye.y > t.height_at(c.eye.x, c.eye.z), "frame {i}");
            assert!(c.target.y < c.eye.y);
        }
        // Water is flat and the island has all five colours.
        let colors = t.colors.as_ref().unwrap();
        for biome in [
            [38, 84, 150],
            [214, 196, 140],
            [120, 110, 100],
            [240, 242, 246],
        ] {
            assert!(colors.contains(&biome), "{biome:?}");
        }
    }

    #[test]
    fn a_square_power_of_two_grid_is_the_same_mesh_in_the_wavelet_engine() {
        let t = Terrain::procedural(33, 5, DEFAULT_VERTICAL_SCALE);
        let grid = t.mesh();
        let s = t.semi_regular().unwrap();
        // The same triangles over the same samples, by position, and every sample's colour.
        let key = |p: [f32; 3]| (p[0] as u32, p[2] as u32, p[1].to_bits());
        let sorted = |positions: &[[f32; 3]], triangles: &[[u32; 3]]| {
            let mut v: Vec<_> = triangles
                .iter()
                .map(|t| {
                    let k = t.map(|i| key(positions[i as usize]));
                    // The same cyclic order from its smallest corner.
                    let m = (0..3).min_by_key(|&i| k[i]).unwrap_or(0);
                    [k[m], k[(m + 1) % 3], k[(m + 2) % 3]]
                })
                .collect();
            v.sort_unstable();
            v
        };
        assert_eq!(
            sorted(&s.positions, &s.finest_triangles()),
            sorted(&grid.positions, &grid.triangles)
        );
        let colors = s.colors.as_ref().unwrap();
        for (p, c) in s.positions.iter().zip(colors) {
            let i = p[2] as usize * 33 + p[0] as usize;
            assert_eq!(*c, t.colors.as_ref().unwrap()[i]);
        }
        // One level at least: 3 x 3 is the smallest.
        for size in [2, 3, 32, 34] {
            let other = Terrain::procedural(size, 5, DEFAULT_VERTICAL_SCALE);
            assert_eq!(other.semi_regular().is_some(), size == 3, "{size}");
        }
    }
}
