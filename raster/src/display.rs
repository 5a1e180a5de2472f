//! [embedded-graphics] interop (feature `embedded-graphics`): its colours as pixel formats, and
//! [`flush`] to send a band to any of its display drivers.
//!
//! Most display drivers for microcontrollers (ST7789, ILI9341, SSD1351 and kin) implement
//! embedded-graphics' [`DrawTarget`]. This module lets a band drawn by the rasterizer reach such a
//! driver without glue code in every integration:
//!
//! - embedded-graphics' [`Rgb565`](EgRgb565), [`Bgr565`] and [`Rgb888`] implement our [`Pixel`],
//!   so a [`Target`] can hold the display's own colour type and be drawn into directly;
//! - `From` conversions join our formats to theirs where no information is lost: [`Rgb565`] and
//!   [`Rgb565Be`] with embedded-graphics' `Rgb565`, [`Rgba8`] with [`Rgb888`] (alpha, which the
//!   rasterizer always writes as 255, is dropped one way and set to 255 the other);
//! - [`flush`] (and [`flush_with`], for a conversion of the caller's choice) sends a target's
//!   window to the display at the window's place in the frame with a single
//!   [`DrawTarget::fill_contiguous`] call, so drivers that stream a rectangle to the panel in one
//!   transaction do so.
//!
//! What it promises:
//!
//! - **Exact colours.** Packing into a 16-bit embedded-graphics colour is our
//!   [`Rgb565::from_rgb`], bit for bit (each channel truncated to its high bits, red in the high
//!   5 bits for `Rgb565`), and unpacking replicates the high bits like [`Rgb565::to_rgb`]. A frame
//!   drawn into a `Target` of embedded-graphics' `Rgb565` therefore holds exactly the bits of the
//!   same frame drawn into our [`Rgb565`]. (embedded-graphics' own conversions between depths
//!   round instead of truncating, so `Rgb565::from(Rgb888)` may differ from `Pixel::from_rgb` in
//!   the last bit: only the `Pixel` impls here are the rasterizer's colours.) The `From`
//!   conversions are lossless between formats of the same depth and round trip.
//! - **Only the window, once.** [`flush`] sends the window's rows top to bottom, each
//!   `area().width` pixels, and never the padding between the end of a row and the next stride;
//!   the display receives one `fill_contiguous` call, never a [`DrawTarget::draw_iter`] call
//!   (though a driver that keeps the trait's default `fill_contiguous` turns it into one itself).
//! - Still `no_std`, allocation-free and without `unsafe`; the display's error is returned as is.
//!
//! [embedded-graphics]: https://docs.rs/embedded-graphics

use embedded_graphics_core::{
    draw_target::DrawTarget,
    geometry::{Point, Size},
    pixelcolor::{
        raw::{RawData, RawU16},
        Bgr565, Rgb565 as EgRgb565, Rgb888, RgbColor,
    },
    primitives::Rectangle,
};

use crate::target::{Depth, Pixel, Rgb565, Rgb565Be, Rgba8, Target};

impl From<Rgb565> for EgRgb565 {
    /// The same 16 bits.
    #[inline]
    fn from(c: Rgb565) -> Self {
        EgRgb565::from(RawU16::new(c.0))
    }
}

impl From<EgRgb565> for Rgb565 {
    /// The same 16 bits.
    #[inline]
    fn from(c: EgRgb565) -> Self {
        Rgb565(RawU16::from(c).into_inner())
    }
}

impl From<Rgb565Be> for EgRgb565 {
    /// The same colour, its bytes read high byte first.
    #[inline]
    fn from(c: Rgb565Be) -> Self {
        Rgb565::from(c).into()
    }
}

impl From<EgRgb565> for Rgb565Be {
    /// The same colour, high byte first.
    #[inline]
    fn from(c: EgRgb565) -> Self {
        Rgb565::from(c).into()
    }
}

impl From<Rgba8> for Rgb888 {
    /// The red, green and blue bytes; alpha is dropped.
    #[inline]
    fn from(c: Rgba8) -> Self {
        Rgb888::new(c.0[0], c.0[1], c.0[2])
    }
}

impl From<Rgb888> for Rgba8 {
    /// The red, green and blue bytes, opaque (alpha 255).
    #[inline]
    fn from(c: Rgb888) -> Self {
        Rgba8([c.r(), c.g(), c.b(), 255])
    }
}

// Exactly [`Rgb565::from_rgb`] and [`Rgb565::to_rgb`].
crate::target::pixel_via_rgb565!(EgRgb565);

impl Pixel for Bgr565 {
    /// The channels of [`Rgb565::from_rgb`], blue in the high bits.
    #[inline(always)]
    fn from_rgb(r: u8, g: u8, b: u8) -> Self {
        Bgr565::new(r >> 3, g >> 2, b >> 3)
    }
    /// As [`Rgb565::to_rgb`].
    #[inline(always)]
    fn to_rgb(self) -> [u8; 3] {
        EgRgb565::new(self.r(), self.g(), self.b()).to_rgb()
    }
}

impl Pixel for Rgb888 {
    #[inline(always)]
    fn from_rgb(r: u8, g: u8, b: u8) -> Self {
        Rgb888::new(r, g, b)
    }
    #[inline(always)]
    fn to_rgb(self) -> [u8; 3] {
        [self.r(), self.g(), self.b()]
    }
}

/// Sends the window of `target` to `display` at the window's position in the frame (the display's
/// origin is the frame's top-left corner), in one [`DrawTarget::fill_contiguous`] call: its rows
/// top to bottom, without the padding of the row stride.
///
/// The target's pixels convert with `Into` (the identity when the target already holds the
/// display's colour type); [`flush_with`] takes any conversion. The display's error is returned
/// unchanged.
///
/// Draw a frame band by band, flushing each before drawing the next:
///
/// ```
/// use embedded_graphics_core::pixelcolor::{Rgb565, RgbColor};
/// use vdlod_raster::{display::flush, Target, Window};
/// # use core::convert::Infallible;
/// # use embedded_graphics_core::{
/// #     draw_target::DrawTarget, geometry::{OriginDimensions, Size}, primitives::Rectangle,
/// # };
/// # /// A 320x240 panel that keeps what it is sent.
/// # struct Panel { pixels: Vec<Rgb565>, fills: usize }
/// # impl OriginDimensions for Panel {
/// #     fn size(&self) -> Size { Size::new(320, 240) }
/// # }
/// # impl DrawTarget for Panel {
/// #     type Color = Rgb565;
/// #     type Error = Infallible;
/// #     fn draw_iter<I>(&mut self, _: I) -> Result<(), Infallible>
/// #     where I: IntoIterator<Item = embedded_graphics_core::Pixel<Rgb565>> {
/// #         unreachable!("flush sends rectangles")
/// #     }
/// #     fn fill_contiguous<I>(&mut self, area: &Rectangle, colors: I) -> Result<(), Infallible>
/// #     where I: IntoIterator<Item = Rgb565> {
/// #         use embedded_graphics_core::primitives::PointsIter;
/// #         for (p, c) in area.points().zip(colors) {
/// #             self.pixels[p.y as usize * 320 + p.x as usize] = c;
/// #         }
/// #         self.fills += 1;
/// #         Ok(())
/// #     }
/// # }
/// let mut panel = Panel { pixels: vec![Rgb565::BLACK; 320 * 240], fills: 0 };
///
/// // 16 rows at a time: 10 KiB of colour (in the panel's own format) and 10 KiB of depth.
/// let mut color = [Rgb565::BLACK; 320 * 16];
/// let mut depth = [0u16; 320 * 16];
/// for band in Window::bands(320, 240, 16) {
///     let mut target = Target::window(&mut color, &mut depth, 320, 240, band, 320).unwrap();
///     target.clear(Rgb565::BLUE);
///     // draw_indexed(&mut target, &mesh, &params, &mut scratch)?; ...
///     flush(&target, &mut panel)?;
/// }
/// assert_eq!(panel.fills, 15);
/// assert!(panel.pixels.iter().all(|&c| c == Rgb565::BLUE));
/// # Ok::<(), Infallible>(())
/// ```
pub fn flush<P, D, T>(target: &Target<'_, P, D>, display: &mut T) -> Result<(), T::Error>
where
    P: Pixel + Into<T::Color>,
    D: Depth,
    T: DrawTarget,
{
    flush_with(target, display, P::into)
}

/// [`flush`] with `convert` turning each pixel into the display's colour, for formats without an
/// `Into` conversion (say an [`Rgba8`] target on an `Rgb565` display:
/// `|p| Pixel::from_rgb(p.0[0], p.0[1], p.0[2])`).
///
/// `convert` is called once per pixel of the window, rows top to bottom, left to right.
pub fn flush_with<P, D, T, F>(
    target: &Target<'_, P, D>,
    display: &mut T,
    convert: F,
) -> Result<(), T::Error>
where
    P: Pixel,
    D: Depth,
    T: DrawTarget,
    F: FnMut(P) -> T::Color,
{
    let area = target.area();
    // Exact: a target's window lies inside a frame of at most MAX_DIMENSION (4096) pixels a side.
    let rectangle = Rectangle::new(
        Point::new(area.x as i32, area.y as i32),
        Size::new(area.width as u32, area.height as u32),
    );
    let colors = (0..area.height)
        .flat_map(|y| target.row(y).iter().copied())
        .map(convert);
    display.fill_contiguous(&rectangle, colors)
}

#[cfg(test)]
mod tests {
    extern crate std;

    use core::convert::Infallible;
    use std::vec::Vec;

    use embedded_graphics_core::{
        geometry::OriginDimensions,
        pixelcolor::{IntoStorage, PixelColor},
    };

    use super::*;
    use crate::{draw_indexed, DrawParams, Mesh, ShadedVertex, Shading, Window};

    /// A display that records every `fill_contiguous` call and counts `draw_iter` calls.
    struct Recorder<C> {
        size: Size,
        fills: Vec<(Rectangle, Vec<C>)>,
        draw_iter_calls: usize,
    }

    impl<C> Recorder<C> {
        fn new(width: u32, height: u32) -> Self {
            Recorder {
                size: Size::new(width, height),
                fills: Vec::new(),
                draw_iter_calls: 0,
            }
        }

        /// The frame the recorded calls paint, `None` where nothing was sent; panics if a
        /// pixel is sent twice or a call's colours do not fill its rectangle exactly.
        fn stitch(&self) -> Vec<Option<C>>
        where
            C: Copy,
        {
            let width = self.size.width as usize;
            let mut frame = std::vec![None; width * self.size.height as usize];
            for (rect, colors) in &self.fills {
                let w = rect.size.width as usize;
                assert_eq!(colors.len(), w * rect.size.height as usize);
                for (i, &c) in colors.iter().enumerate() {
                    let x = rect.top_left.x as usize + i % w;
                    let y = rect.top_left.y as usize + i / w;
                    let slot = &mut frame[y * width + x];
                    assert!(slot.is_none(), "pixel ({x}, {y}) sent twice");
                    *slot = Some(c);
                }
            }
            frame
        }
    }

    impl<C> OriginDimensions for Recorder<C> {
        fn size(&self) -> Size {
            self.size
        }
    }

    impl<C: PixelColor> DrawTarget for Recorder<C> {
        type Color = C;
        type Error = Infallible;

        fn draw_iter<I>(&mut self, _pixels: I) -> Result<(), Infallible>
        where
            I: IntoIterator<Item = embedded_graphics_core::Pixel<C>>,
        {
            self.draw_iter_calls += 1;
            Ok(())
        }

        fn fill_contiguous<I>(&mut self, area: &Rectangle, colors: I) -> Result<(), Infallible>
        where
            I: IntoIterator<Item = C>,
        {
            self.fills.push((*area, colors.into_iter().collect()));
            Ok(())
        }
    }

    fn rect(x: i32, y: i32, width: u32, height: u32) -> Rectangle {
        Rectangle::new(Point::new(x, y), Size::new(width, height))
    }

    /// Channel values covering every 5- and 6-bit bucket at both ends and in the middle.
    fn channels() -> impl Iterator<Item = u8> + Clone {
        (0..=255u8).filter(|v| v % 4 == 0 || v % 8 == 3 || v % 8 == 7)
    }

    #[test]
    fn rgb565_matches_our_bit_layout() {
        for r in channels() {
            for g in channels() {
                for b in channels().step_by(3) {
                    let ours = Rgb565::from_rgb(r, g, b);
                    let expected = EgRgb565::new(r >> 3, g >> 2, b >> 3);
                    assert_eq!(EgRgb565::from(ours), expected, "({r}, {g}, {b})");
                    assert_eq!(EgRgb565::from_rgb(r, g, b), expected);
                    assert_eq!(EgRgb565::from(Rgb565Be::from_rgb(r, g, b)), expected);
                    assert_eq!(
                        Bgr565::from_rgb(r, g, b),
                        Bgr565::new(r >> 3, g >> 2, b >> 3)
                    );
                    assert_eq!(
                        Bgr565::from_rgb(r, g, b).to_rgb(),
                        ours.to_rgb(),
                        "({r}, {g}, {b})"
                    );
                    assert_eq!(Rgb888::from_rgb(r, g, b), Rgb888::new(r, g, b));
                    assert_eq!(Rgb888::from(Rgba8::from_rgb(r, g, b)), Rgb888::new(r, g, b));
                }
            }
        }
        // Red in the high bits, as in our format.
        assert_eq!(EgRgb565::from(Rgb565(0xF800)), EgRgb565::RED);
        assert_eq!(EgRgb565::from(Rgb565(0x07E0)), EgRgb565::GREEN);
        assert_eq!(EgRgb565::from(Rgb565(0x001F)), EgRgb565::BLUE);
        assert_eq!(EgRgb565::from(Rgb565Be([0xF8, 0x00])), EgRgb565::RED);
    }

    #[test]
    fn sixteen_bit_conversions_round_trip() {
        for v in 0..=u16::MAX {
            let ours = Rgb565(v);
            let eg = EgRgb565::from(ours);
            assert_eq!(eg.into_storage(), v);
            assert_eq!(Rgb565::from(eg), ours);
            assert_eq!(eg.to_rgb(), ours.to_rgb());
            assert_eq!(
                EgRgb565::from_rgb(eg.to_rgb()[0], eg.to_rgb()[1], eg.to_rgb()[2]),
                eg
            );
            let be = Rgb565Be::from(ours);
            assert_eq!(EgRgb565::from(be), eg);
            assert_eq!(Rgb565Be::from(eg), be);
            let bgr = Bgr565::new(eg.r(), eg.g(), eg.b());
            assert_eq!(bgr.to_rgb(), ours.to_rgb());
            let [r, g, b] = bgr.to_rgb();
            assert_eq!(Bgr565::from_rgb(r, g, b), bgr);
        }
    }

    #[test]
    fn rgb888_round_trips() {
        for r in channels() {
            for g in channels() {
                let b = r.wrapping_mul(7) ^ g;
                let c = Rgb888::new(r, g, b);
                assert_eq!(Rgba8::from(c), Rgba8([r, g, b, 255]));
                assert_eq!(Rgb888::from(Rgba8::from(c)), c);
                assert_eq!(c.to_rgb(), [r, g, b]);
                assert_eq!(Rgb888::from(Rgba8([r, g, b, 7])), c);
            }
        }
    }

    /// A gradient square drawn into `target`, the same for every pixel format.
    fn draw_square<P: Pixel>(color: &mut [P], width: usize, height: usize) {
        let positions = [
            [-1.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
        ];
        let colors = [[255, 0, 30], [10, 250, 0], [0, 40, 255], [200, 200, 5]];
        let triangles: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];
        let mesh = Mesh {
            positions: &positions,
            colors: Some(&colors),
            triangles: &triangles,
            ..Mesh::default()
        };
        let params = DrawParams {
            mvp: glam::Mat4::from_scale(glam::Vec3::new(0.9, 0.8, 0.5)),
            shading: Shading::Unlit,
            ..DrawParams::default()
        };
        let mut depth = std::vec![0u32; width * height];
        let mut target = Target::new(color, &mut depth, width, height).unwrap();
        target.clear(P::from_rgb(1, 2, 3));
        let mut scratch = [ShadedVertex::default(); 4];
        draw_indexed(&mut target, &mesh, &params, &mut scratch).unwrap();
    }

    #[test]
    fn drawing_in_embedded_graphics_colours_gives_the_same_bits() {
        let (w, h) = (37, 29);
        let mut ours = std::vec![Rgb565(0); w * h];
        let mut eg = std::vec![EgRgb565::BLACK; w * h];
        let mut bgr = std::vec![Bgr565::BLACK; w * h];
        let mut rgba = std::vec![Rgba8::default(); w * h];
        let mut rgb888 = std::vec![Rgb888::BLACK; w * h];
        draw_square(&mut ours, w, h);
        draw_square(&mut eg, w, h);
        draw_square(&mut bgr, w, h);
        draw_square(&mut rgba, w, h);
        draw_square(&mut rgb888, w, h);
        let distinct = {
            let mut v: Vec<u16> = ours.iter().map(|c| c.0).collect();
            v.sort_unstable();
            v.dedup();
            v.len()
        };
        assert!(distinct > 50, "the gradient should have many colours");
        for i in 0..w * h {
            assert_eq!(EgRgb565::from(ours[i]), eg[i]);
            assert_eq!(bgr[i].to_rgb(), ours[i].to_rgb());
            assert_eq!(Rgb888::from(rgba[i]), rgb888[i]);
        }
    }

    #[test]
    fn bands_flush_as_one_call_each_without_padding() {
        const W: usize = 12;
        const H: usize = 10;
        const ROWS: usize = 4;
        const STRIDE: usize = 14;
        const PADDING: u16 = 0xFFFF;
        let mut display = Recorder::<EgRgb565>::new(W as u32, H as u32);
        let mut color = [Rgb565(PADDING); ROWS * STRIDE];
        let mut depth = [0u16; ROWS * STRIDE];
        for band in Window::bands(W, H, ROWS) {
            // Each pixel holds its index in the frame; the padding keeps the sentinel.
            color.fill(Rgb565(PADDING));
            for y in 0..band.height {
                for x in 0..band.width {
                    color[y * STRIDE + x] = Rgb565(((band.y + y) * W + band.x + x) as u16);
                }
            }
            let target = Target::window(&mut color, &mut depth, W, H, band, STRIDE).unwrap();
            flush(&target, &mut display).unwrap();
        }
        assert_eq!(display.draw_iter_calls, 0);
        let rects: Vec<Rectangle> = display.fills.iter().map(|f| f.0).collect();
        assert_eq!(
            rects,
            [rect(0, 0, 12, 4), rect(0, 4, 12, 4), rect(0, 8, 12, 2)]
        );
        for (_, colors) in &display.fills {
            assert!(colors.iter().all(|c| c.into_storage() != PADDING));
        }
        let frame = display.stitch();
        for (i, c) in frame.iter().enumerate() {
            assert_eq!(
                c.map(IntoStorage::into_storage),
                Some(i as u16),
                "pixel {i}"
            );
        }
    }

    #[test]
    fn a_tile_lands_at_its_place() {
        // A 5x3 window at (4, 6) of a 12x10 frame, stride 8, big-endian pixels.
        let window = Window {
            x: 4,
            y: 6,
            width: 5,
            height: 3,
        };
        let mut color = [Rgb565Be([0xFF, 0xFF]); 3 * 8];
        let mut depth = [0u32; 3 * 8];
        for y in 0..3 {
            for x in 0..5 {
                color[y * 8 + x] = Rgb565((y * 5 + x) as u16).into();
            }
        }
        let target = Target::window(&mut color, &mut depth, 12, 10, window, 8).unwrap();
        let mut display = Recorder::<EgRgb565>::new(12, 10);
        flush(&target, &mut display).unwrap();
        assert_eq!(display.draw_iter_calls, 0);
        assert_eq!(display.fills.len(), 1);
        assert_eq!(display.fills[0].0, rect(4, 6, 5, 3));
        let sent: Vec<u16> = display.fills[0]
            .1
            .iter()
            .map(|c| c.into_storage())
            .collect();
        assert_eq!(sent, (0..15).collect::<Vec<u16>>());
    }

    #[test]
    fn a_whole_frame_flushes_as_one_call() {
        let mut color: Vec<Rgba8> = (0..12 * 10)
            .map(|i| Rgba8([i as u8, 255 - i as u8, (i * 3) as u8, 255]))
            .collect();
        let mut depth = [0u32; 12 * 10];
        let target = Target::new(&mut color, &mut depth, 12, 10).unwrap();
        let mut display = Recorder::<Rgb888>::new(12, 10);
        flush(&target, &mut display).unwrap();
        assert_eq!(display.draw_iter_calls, 0);
        assert_eq!(display.fills.len(), 1);
        assert_eq!(display.fills[0].0, rect(0, 0, 12, 10));
        let expected: Vec<Rgb888> = target.color().iter().map(|&c| c.into()).collect();
        assert_eq!(display.fills[0].1, expected);

        // The same frame on a 16-bit panel, through a conversion closure.
        let mut panel = Recorder::<EgRgb565>::new(12, 10);
        flush_with(&target, &mut panel, |p| {
            let [r, g, b] = p.to_rgb();
            EgRgb565::from_rgb(r, g, b)
        })
        .unwrap();
        assert_eq!(panel.fills.len(), 1);
        let expected: Vec<EgRgb565> = target
            .color()
            .iter()
            .map(|c| Rgb565::from_rgb(c.0[0], c.0[1], c.0[2]).into())
            .collect();
        assert_eq!(panel.fills[0].1, expected);
    }

    #[test]
    fn display_errors_pass_through() {
        struct Broken;
        impl OriginDimensions for Broken {
            fn size(&self) -> Size {
                Size::new(4, 4)
            }
        }
        impl DrawTarget for Broken {
            type Color = Rgb888;
            type Error = &'static str;
            fn draw_iter<I>(&mut self, _: I) -> Result<(), &'static str>
            where
                I: IntoIterator<Item = embedded_graphics_core::Pixel<Rgb888>>,
            {
                Err("draw_iter")
            }
            fn fill_contiguous<I>(&mut self, _: &Rectangle, _: I) -> Result<(), &'static str>
            where
                I: IntoIterator<Item = Rgb888>,
            {
                Err("bus error")
            }
        }
        let mut color = [Rgb888::BLACK; 16];
        let mut depth = [0u32; 16];
        let target = Target::new(&mut color, &mut depth, 4, 4).unwrap();
        assert_eq!(flush(&target, &mut Broken), Err("bus error"));
    }
}
