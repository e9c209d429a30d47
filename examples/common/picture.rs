//! Pictures for the examples: a supersampled RGB canvas that plotters draws on, saved as
//! PNG or gathered into an animated GIF.
//!
//! plotters' bitmap backend does not smooth the edges of lines and circles, so every
//! picture is drawn at [`SUPERSAMPLE`] times its size and averaged down (a box filter over
//! `SUPERSAMPLE²` pixels): edges come out antialiased at no cost in code. Drawing code
//! works in *logical* pixels of the final picture; [`Canvas`] scales coordinates, line
//! widths and font sizes. Text uses DejaVu Sans embedded from `examples/assets` (its
//! licence is beside it), so pictures draw the same on a machine without system fonts.

use std::fs::File;
use std::io::{self, BufWriter};
use std::path::Path;
use std::sync::Once;

use plotters::backend::BitMapBackend;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Each logical pixel is drawn as `SUPERSAMPLE × SUPERSAMPLE` pixels, then averaged.
pub(crate) const SUPERSAMPLE: u32 = 3;

/// The font family name every picture uses.
pub(crate) const FONT: &str = "sans-serif";

static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the embedded font with plotters (once per process).
pub(crate) fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        assert!(
            plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok(),
            "the embedded DejaVu Sans is a valid TrueType font"
        );
    });
}

/// Titles and text.
pub(crate) const INK: RGBColor = RGBColor(40, 44, 52);
/// Settings, labels and ticks.
pub(crate) const MUTED: RGBColor = RGBColor(110, 116, 128);

/// Colours for balls: the Okabe–Ito palette, readable for colour-blind viewers.
pub(crate) const BALL_COLOURS: [RGBColor; 8] = [
    RGBColor(230, 159, 0),
    RGBColor(0, 114, 178),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(213, 94, 0),
    RGBColor(86, 180, 233),
    RGBColor(240, 228, 66),
    RGBColor(0, 0, 0),
];

/// The colour of ball `i`.
pub(crate) fn ball_colour(i: usize) -> RGBColor {
    BALL_COLOURS[i % BALL_COLOURS.len()]
}

/// `c` mixed with white: `amount = 0` is `c`, `1` is white.
pub(crate) fn lighter(c: RGBColor, amount: f64) -> RGBColor {
    let mix = |x: u8| (f64::from(x) + (255.0 - f64::from(x)) * amount).round() as u8;
    RGBColor(mix(c.0), mix(c.1), mix(c.2))
}

/// `c` mixed with black: `amount = 0` is `c`, `1` is black.
pub(crate) fn darker(c: RGBColor, amount: f64) -> RGBColor {
    let mix = |x: u8| (f64::from(x) * (1.0 - amount)).round() as u8;
    RGBColor(mix(c.0), mix(c.1), mix(c.2))
}

/// Where text sits relative to its anchor point.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Anchor {
    /// The anchor is the left end of the text's middle line.
    Left,
    /// The anchor is the centre of the text.
    Centre,
    /// The anchor is the right end of the text's middle line.
    Right,
}

/// An RGB picture drawn supersampled.
pub(crate) struct Raster {
    width: u32,
    height: u32,
    /// `width · S × height · S` RGB pixels.
    big: Vec<u8>,
}

impl Raster {
    /// A white picture of `width × height` logical pixels.
    pub(crate) fn new(width: u32, height: u32) -> Self {
        register_font();
        let n = (width * SUPERSAMPLE) as usize * (height * SUPERSAMPLE) as usize * 3;
        Self {
            width,
            height,
            big: vec![255; n],
        }
    }

    /// Logical width.
    pub(crate) fn width(&self) -> u32 {
        self.width
    }

    /// Logical height.
    pub(crate) fn height(&self) -> u32 {
        self.height
    }

    /// Clears to white.
    pub(crate) fn clear(&mut self) {
        self.big.fill(255);
    }

    /// Draws with `f` on a [`Canvas`] over the whole picture.
    ///
    /// # Errors
    /// What `f` returns.
    pub(crate) fn draw<R>(
        &mut self,
        f: impl FnOnce(&Canvas<'_>) -> Result<R, Box<dyn std::error::Error>>,
    ) -> Result<R, Box<dyn std::error::Error>> {
        let size = (self.width * SUPERSAMPLE, self.height * SUPERSAMPLE);
        let area = BitMapBackend::with_buffer(&mut self.big, size).into_drawing_area();
        let canvas = Canvas { area };
        let out = f(&canvas)?;
        canvas.area.present()?;
        Ok(out)
    }

    /// The picture at its logical size: each pixel the mean of its `S × S` block.
    pub(crate) fn pixels(&self) -> Vec<u8> {
        let s = SUPERSAMPLE as usize;
        let (w, h) = (self.width as usize, self.height as usize);
        let big_w = w * s;
        let mut out = vec![0u8; w * h * 3];
        let norm = (s * s) as u32;
        for y in 0..h {
            for x in 0..w {
                for c in 0..3 {
                    let mut sum = 0u32;
                    for dy in 0..s {
                        let row = (y * s + dy) * big_w;
                        for dx in 0..s {
                            sum += u32::from(self.big[(row + x * s + dx) * 3 + c]);
                        }
                    }
                    out[(y * w + x) * 3 + c] = ((sum + norm / 2) / norm) as u8;
                }
            }
        }
        out
    }

    /// Writes the picture as an 8-bit RGB PNG.
    ///
    /// # Errors
    /// The file cannot be created or written.
    pub(crate) fn save_png(&self, path: &Path) -> io::Result<()> {
        let file = BufWriter::new(File::create(path)?);
        let mut encoder = png::Encoder::new(file, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(io::Error::other)?;
        writer
            .write_image_data(&self.pixels())
            .map_err(io::Error::other)?;
        writer.finish().map_err(io::Error::other)
    }
}

/// An animated GIF, one [`Raster`] per frame.
pub(crate) struct Animation {
    encoder: gif::Encoder<BufWriter<File>>,
    width: u16,
    height: u16,
    delay_cs: u16,
}

impl Animation {
    /// A looping GIF of `width × height` frames shown `delay_cs` hundredths of a second each.
    ///
    /// # Errors
    /// The file cannot be created, or the size does not fit a GIF (65535 pixels).
    pub(crate) fn create(path: &Path, width: u32, height: u32, delay_cs: u16) -> io::Result<Self> {
        let too_big = || io::Error::other("a GIF is at most 65535 pixels wide and high");
        let (width, height) = (
            u16::try_from(width).map_err(|_| too_big())?,
            u16::try_from(height).map_err(|_| too_big())?,
        );
        let file = BufWriter::new(File::create(path)?);
        let mut encoder = gif::Encoder::new(file, width, height, &[]).map_err(io::Error::other)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(io::Error::other)?;
        Ok(Self {
            encoder,
            width,
            height,
            delay_cs,
        })
    }

    /// Appends `frame` (quantised to 256 colours).
    ///
    /// # Errors
    /// The frame has another size than the animation, or cannot be written.
    pub(crate) fn push(&mut self, frame: &Raster) -> io::Result<()> {
        if (frame.width(), frame.height()) != (u32::from(self.width), u32::from(self.height)) {
            return Err(io::Error::other("every frame of an animation has one size"));
        }
        let mut f = gif::Frame::from_rgb_speed(self.width, self.height, &frame.pixels(), 10);
        f.delay = self.delay_cs;
        self.encoder.write_frame(&f).map_err(io::Error::other)
    }
}

/// Drawing in logical pixels on a supersampled area.
pub(crate) struct Canvas<'a> {
    area: DrawingArea<BitMapBackend<'a>, Shift>,
}

/// A point in logical pixels (x right, y down).
pub(crate) type Px = (f64, f64);

fn big(p: Px) -> (i32, i32) {
    let s = f64::from(SUPERSAMPLE);
    ((p.0 * s).round() as i32, (p.1 * s).round() as i32)
}

fn big_len(x: f64) -> u32 {
    (x * f64::from(SUPERSAMPLE)).round().max(1.0) as u32
}

type Drawn = Result<(), Box<dyn std::error::Error>>;

impl<'a> Canvas<'a> {
    /// The underlying plotters area (supersampled pixels) for charts.
    pub(crate) fn area(&self) -> &DrawingArea<BitMapBackend<'a>, Shift> {
        &self.area
    }

    /// A font size in logical pixels, scaled for the supersampled area.
    pub(crate) fn font_size(size: f64) -> f64 {
        size * f64::from(SUPERSAMPLE)
    }

    /// A length in logical pixels, scaled for the supersampled area.
    pub(crate) fn scaled(len: f64) -> u32 {
        big_len(len)
    }

    /// A polyline of `width` logical pixels.
    pub(crate) fn polyline(&self, points: &[Px], colour: RGBAColor, width: f64) -> Drawn {
        if points.len() < 2 {
            return Ok(());
        }
        let pts: Vec<(i32, i32)> = points.iter().map(|&p| big(p)).collect();
        self.area
            .draw(&PathElement::new(pts, colour.stroke_width(big_len(width))))?;
        Ok(())
    }

    /// A filled polygon.
    pub(crate) fn polygon(&self, points: &[Px], colour: RGBAColor) -> Drawn {
        let pts: Vec<(i32, i32)> = points.iter().map(|&p| big(p)).collect();
        self.area.draw(&Polygon::new(pts, colour.filled()))?;
        Ok(())
    }

    /// A filled rectangle between two corners.
    pub(crate) fn fill_rect(&self, a: Px, b: Px, colour: RGBAColor) -> Drawn {
        self.area
            .draw(&Rectangle::new([big(a), big(b)], colour.filled()))?;
        Ok(())
    }

    /// A rectangle outline.
    pub(crate) fn stroke_rect(&self, a: Px, b: Px, colour: RGBAColor, width: f64) -> Drawn {
        self.area.draw(&Rectangle::new(
            [big(a), big(b)],
            colour.stroke_width(big_len(width)),
        ))?;
        Ok(())
    }

    /// A disk with an outline (`outline` of width 0 draws none).
    pub(crate) fn disk(
        &self,
        centre: Px,
        radius: f64,
        fill: RGBAColor,
        outline: RGBAColor,
        width: f64,
    ) -> Drawn {
        let c = big(centre);
        let r = big_len(radius);
        self.area.draw(&Circle::new(c, r, fill.filled()))?;
        if width > 0.0 {
            self.area
                .draw(&Circle::new(c, r, outline.stroke_width(big_len(width))))?;
        }
        Ok(())
    }

    /// A circle outline.
    pub(crate) fn ring(&self, centre: Px, radius: f64, colour: RGBAColor, width: f64) -> Drawn {
        self.area.draw(&Circle::new(
            big(centre),
            big_len(radius),
            colour.stroke_width(big_len(width)),
        ))?;
        Ok(())
    }

    /// An arrow from `from` to `to` with a shaft of `width` and a head of length `head`
    /// (shorter arrows get proportionally smaller heads). Arrows shorter than a pixel are
    /// not drawn.
    pub(crate) fn arrow(
        &self,
        from: Px,
        to: Px,
        colour: RGBAColor,
        width: f64,
        head: f64,
    ) -> Drawn {
        let (dx, dy) = (to.0 - from.0, to.1 - from.1);
        let len = dx.hypot(dy);
        if len < 1.0 {
            return Ok(());
        }
        let (ux, uy) = (dx / len, dy / len);
        let head = head.min(0.6 * len);
        let half = head * 0.45;
        let base = (to.0 - ux * head, to.1 - uy * head);
        self.polyline(&[from, (base.0 + ux, base.1 + uy)], colour, width)?;
        self.polygon(
            &[
                to,
                (base.0 - uy * half, base.1 + ux * half),
                (base.0 + uy * half, base.1 - ux * half),
            ],
            colour,
        )
    }

    /// A picture's header on a canvas `width` logical pixels wide: the title and, under
    /// it, the settings on the left, the time `t` (s) on the right.
    pub(crate) fn header(&self, title: &str, settings: &str, t: f64, width: f64) -> Drawn {
        self.text(title, (20.0, 22.0), 22.0, INK, Anchor::Left)?;
        self.text(settings, (20.0, 50.0), 14.0, MUTED, Anchor::Left)?;
        self.text(
            &format!("t = {t:.2} s"),
            (width - 20.0, 22.0),
            22.0,
            INK,
            Anchor::Right,
        )
    }

    /// Text of `size` logical pixels anchored at `at`.
    pub(crate) fn text(
        &self,
        s: &str,
        at: Px,
        size: f64,
        colour: RGBColor,
        anchor: Anchor,
    ) -> Drawn {
        let h = match anchor {
            Anchor::Left => HPos::Left,
            Anchor::Centre => HPos::Center,
            Anchor::Right => HPos::Right,
        };
        let style = TextStyle::from((FONT, Self::font_size(size)).into_font())
            .color(&colour)
            .pos(Pos::new(h, VPos::Center));
        self.area.draw(&Text::new(s.to_owned(), big(at), style))?;
        Ok(())
    }
}

/// A map from world coordinates (metres, y up) to logical pixels (y down) at one scale
/// on both axes, so shapes keep their proportions.
#[derive(Clone, Copy, Debug)]
pub(crate) struct View {
    /// The world point drawn at `origin_px`.
    pub(crate) origin: (f64, f64),
    /// Where `origin` lands, in logical pixels.
    pub(crate) origin_px: Px,
    /// Logical pixels per metre.
    pub(crate) scale: f64,
}

impl View {
    /// The view that fits the world rectangle `min..max` into the pixel rectangle
    /// `px_min..px_max`, centred, one scale on both axes.
    pub(crate) fn fit(min: (f64, f64), max: (f64, f64), px_min: Px, px_max: Px) -> Self {
        let scale =
            ((px_max.0 - px_min.0) / (max.0 - min.0)).min((px_max.1 - px_min.1) / (max.1 - min.1));
        let centre = (f64::midpoint(min.0, max.0), f64::midpoint(min.1, max.1));
        let centre_px = (
            f64::midpoint(px_min.0, px_max.0),
            f64::midpoint(px_min.1, px_max.1),
        );
        Self {
            origin: centre,
            origin_px: centre_px,
            scale,
        }
    }

    /// The pixel of world point `p`.
    pub(crate) fn px(&self, p: (f64, f64)) -> Px {
        (
            self.origin_px.0 + (p.0 - self.origin.0) * self.scale,
            self.origin_px.1 - (p.1 - self.origin.1) * self.scale,
        )
    }

    /// A world length in pixels.
    pub(crate) fn len(&self, metres: f64) -> f64 {
        metres * self.scale
    }
}

/// A named line of a chart: `(name, colour, points)`.
pub(crate) type Series<'a> = (&'a str, RGBColor, Vec<(f64, f64)>);

/// A line chart on `panel` with its caption, the `x` range, one line per series (with a
/// legend) and vertical lines at `marks` (x, colour). The y range fits the data with a
/// margin.
///
/// # Errors
/// Drawing fails.
pub(crate) fn line_chart(
    panel: &DrawingArea<BitMapBackend<'_>, Shift>,
    caption: &str,
    x_desc: &str,
    x: std::ops::Range<f64>,
    lines: &[Series<'_>],
    marks: &[(f64, RGBColor)],
) -> Drawn {
    let muted = RGBColor(110, 116, 128);
    let grid = RGBColor(226, 231, 238);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, _, pts) in lines {
        for &(_, y) in pts {
            lo = lo.min(y);
            hi = hi.max(y);
        }
    }
    if !(lo.is_finite() && hi.is_finite()) {
        (lo, hi) = (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.15)
        .max(0.05 * hi.abs().max(lo.abs()))
        .max(1e-3);
    let (lo, hi) = (lo - pad, hi + pad);
    let font = |size: f64| (FONT, Canvas::font_size(size)).into_font();
    let mut chart = ChartBuilder::on(panel)
        .margin(Canvas::scaled(12.0))
        .caption(caption, font(16.0))
        .x_label_area_size(Canvas::scaled(34.0))
        .y_label_area_size(Canvas::scaled(80.0))
        .build_cartesian_2d(x, lo..hi)?;
    chart
        .configure_mesh()
        .light_line_style(RGBAColor(0, 0, 0, 0.0))
        .bold_line_style(grid.stroke_width(Canvas::scaled(1.0)))
        .axis_style(muted.stroke_width(Canvas::scaled(1.0)))
        .label_style(font(12.0).color(&muted))
        .x_desc(x_desc)
        .axis_desc_style(font(12.0).color(&muted))
        .x_labels(11)
        .y_labels(5)
        .draw()?;
    for &(at, colour) in marks {
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(at, lo), (at, hi)],
            colour.stroke_width(Canvas::scaled(1.0)),
        )))?;
    }
    for (name, colour, pts) in lines {
        let colour = *colour;
        chart
            .draw_series(LineSeries::new(
                pts.iter().copied(),
                colour.stroke_width(Canvas::scaled(2.5)),
            ))?
            .label(*name)
            .legend(move |(x, y)| {
                PathElement::new(
                    vec![(x, y), (x + Canvas::scaled(24.0) as i32, y)],
                    colour.stroke_width(Canvas::scaled(3.0)),
                )
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .legend_area_size(Canvas::scaled(34.0))
        .margin(Canvas::scaled(8.0))
        .background_style(WHITE.mix(0.85))
        .border_style(grid)
        .label_font(font(13.0))
        .draw()?;
    Ok(())
}
