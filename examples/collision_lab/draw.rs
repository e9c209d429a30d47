//! The pictures: the play area to scale with ball paths, velocity and momentum arrows,
//! the centre of mass and the collisions; the quantities over time; an animated GIF.

use std::error::Error;
use std::path::{Path, PathBuf};

use carom::sim::Collision;
use nalgebra::Vector2;
use plotters::prelude::*;

use super::lab::{Record, case_name, cluster_spin, groups, is_1d, quantities, screen_of};
use super::picture::{
    Anchor, Animation, Canvas, INK, MUTED, Px, Raster, Series, View, ball_colour, darker, lighter,
    line_chart,
};
use super::report::{bodies_at, settings, title};
use carom::sim::scenes::collision_lab::play_area;

/// Drawn length of a velocity arrow per m/s (m).
const VELOCITY_SCALE: f64 = 0.4;
/// Drawn length of a momentum arrow per kg·m/s (m).
const MOMENTUM_SCALE: f64 = 0.4;

const AREA: RGBColor = RGBColor(246, 248, 251);
const GRID: RGBColor = RGBColor(226, 231, 238);
const COM: RGBColor = RGBColor(60, 60, 60);
/// The total momentum arrow.
const TOTAL: RGBColor = RGBColor(178, 24, 43);

type Drawn = Result<(), Box<dyn Error>>;

fn xy(v: &Vector2<f64>) -> (f64, f64) {
    (v.x, v.y)
}

/// A ball–ball contact: a diamond at `p` with its number (as in the collision table)
/// `rise` pixels above and to the right.
fn contact_marker(canvas: &Canvas<'_>, p: Px, number: usize, rise: f64) -> Drawn {
    let s = 5.0;
    canvas.polygon(
        &[
            (p.0, p.1 - s),
            (p.0 + s, p.1),
            (p.0, p.1 + s),
            (p.0 - s, p.1),
        ],
        INK.to_rgba(),
    )?;
    canvas.text(
        &format!("{number}"),
        (p.0 + 7.0, p.1 - rise),
        12.0,
        INK,
        Anchor::Left,
    )
}

/// What a play-area picture shows.
#[derive(Clone, Copy)]
struct Layers {
    /// Index of the last frame drawn (the "now" of the picture).
    upto: usize,
    /// Collision markers with their table numbers.
    markers: bool,
    /// The start positions and velocities, faint.
    start: bool,
    /// The legend and quantities below the play area.
    legend: bool,
}

/// The pixel layout of a play-area picture of `width` logical pixels.
struct Layout {
    view: View,
    width: u32,
    height: u32,
    area_min: Px,
    area_max: Px,
    /// On 1D screens: the top and bottom of the space-time diagram below the play area.
    spacetime: Option<(f64, f64)>,
}

fn layout(record: &Record, width: u32, legend: bool) -> Layout {
    let area = play_area(screen_of(record.case));
    let (min, max) = (area.min(), area.max());
    let margin = 0.12;
    let header = 70.0;
    let (left, right) = (50.0, 20.0);
    let footer = if legend { 150.0 } else { 40.0 };
    let scale = (f64::from(width) - left - right) / (max.x - min.x + 2.0 * margin);
    let plot_h = (max.y - min.y + 2.0 * margin) * scale;
    let diagram = if is_1d(record.case) {
        f64::from(width) * 0.32
    } else {
        0.0
    };
    let height = (header + plot_h + diagram + footer).round() as u32;
    let view = View::fit(
        (min.x - margin, min.y - margin),
        (max.x + margin, max.y + margin),
        (left, header),
        (f64::from(width) - right, header + plot_h),
    );
    Layout {
        area_min: view.px((min.x, max.y)),
        area_max: view.px((max.x, min.y)),
        spacetime: (diagram > 0.0).then_some((header + plot_h + 60.0, header + plot_h + diagram)),
        view,
        width,
        height,
    }
}

fn play(canvas: &Canvas<'_>, record: &Record, l: &Layout, layers: Layers) -> Drawn {
    let frames = &record.frames[..=layers.upto];
    let now = &frames[frames.len() - 1];
    header(canvas, record, l, now.t)?;
    grid(canvas, record, l)?;
    if layers.start {
        start_positions(canvas, record, l)?;
    }
    let clusters = groups(&bodies_at(record, now.t));
    cluster_snapshots(canvas, record, l, frames, &clusters)?;
    if let Some((top, bottom)) = l.spacetime {
        spacetime(canvas, record, l, layers.upto, top, bottom)?;
    }
    paths(canvas, record, l, frames)?;
    if layers.markers && l.spacetime.is_none() {
        markers(canvas, record, l, now.t)?;
    }
    balls_now(canvas, record, l, &now.states, &clusters)?;
    if layers.legend {
        legend(canvas, record, l, now.t)?;
    } else {
        let y = l.spacetime.map_or(l.area_max.1, |(_, bottom)| bottom) + 28.0;
        canvas.text(
            "dark arrows: velocity (1 m/s = 0.4 m)  ·  coloured arrows: momentum (1 kg·m/s = 0.4 m)  ·  red: total momentum at the centre of mass ⊗  ·  grid 0.5 m",
            (20.0, y),
            12.0,
            MUTED,
            Anchor::Left,
        )?;
    }
    Ok(())
}

/// The title, the settings and the time.
fn header(canvas: &Canvas<'_>, record: &Record, l: &Layout, t: f64) -> Drawn {
    let settings = format!("{}; grid 0.5 m", settings(record));
    canvas.header(&title(record), &settings, t, f64::from(l.width))
}

/// The play area with a 0.5 m grid, tick labels and its border.
fn grid(canvas: &Canvas<'_>, record: &Record, l: &Layout) -> Drawn {
    let v = &l.view;
    let scene = &record.scene;
    let area = play_area(screen_of(record.case));
    // The play area with a 0.5 m grid and tick labels.
    canvas.fill_rect(l.area_min, l.area_max, AREA.to_rgba())?;
    let mut x = (area.min().x * 2.0).ceil() / 2.0;
    while x <= area.max().x + 1e-9 {
        canvas.polyline(
            &[v.px((x, area.min().y)), v.px((x, area.max().y))],
            GRID.to_rgba(),
            1.0,
        )?;
        canvas.text(
            &format!("{x:+.1}").replace("+0.0", "0"),
            v.px((x, area.min().y - 0.07)),
            12.0,
            MUTED,
            Anchor::Centre,
        )?;
        x += 0.5;
    }
    let mut y = (area.min().y * 2.0).ceil() / 2.0;
    while y <= area.max().y + 1e-9 {
        canvas.polyline(
            &[v.px((area.min().x, y)), v.px((area.max().x, y))],
            GRID.to_rgba(),
            1.0,
        )?;
        let at = v.px((area.min().x, y));
        canvas.text(
            &format!("{y:+.1}").replace("+0.0", "0"),
            (at.0 - 8.0, at.1),
            12.0,
            MUTED,
            Anchor::Right,
        )?;
        y += 0.5;
    }
    let border_colour = if scene.world.border.is_some() {
        INK.to_rgba()
    } else {
        lighter(INK, 0.7).to_rgba()
    };
    canvas.stroke_rect(
        l.area_min,
        l.area_max,
        border_colour,
        if scene.world.border.is_some() {
            3.0
        } else {
            1.0
        },
    )?;
    Ok(())
}

/// The start positions and velocities, faint.
fn start_positions(canvas: &Canvas<'_>, record: &Record, l: &Layout) -> Drawn {
    let v = &l.view;
    let scene = &record.scene;
    // Start positions and velocities, faint.
    let first = &record.frames[0].states;
    {
        for (k, b) in scene.balls.iter().enumerate() {
            let c = v.px(xy(&first.pos[k]));
            canvas.disk(
                c,
                v.len(b.radius),
                lighter(ball_colour(k), 0.78).to_rgba(),
                lighter(ball_colour(k), 0.4).to_rgba(),
                1.0,
            )?;
            canvas.arrow(
                c,
                v.px(xy(&(first.pos[k] + first.vel[k] * VELOCITY_SCALE))),
                lighter(INK, 0.55).to_rgba(),
                2.0,
                12.0,
            )?;
            canvas.text(
                &format!("{}", k + 1),
                c,
                14.0,
                lighter(INK, 0.45),
                Anchor::Centre,
            )?;
        }
    }
    Ok(())
}

/// Stuck clusters: faint snapshots show the rotation, at least 0.1 s apart and about a
/// dozen over the run.
fn cluster_snapshots(
    canvas: &Canvas<'_>,
    record: &Record,
    l: &Layout,
    frames: &[super::lab::Frame],
    clusters: &[Vec<usize>],
) -> Drawn {
    let v = &l.view;
    let scene = &record.scene;
    // Stuck clusters: faint snapshots show the rotation, at least 0.1 s apart and
    // about a dozen over the run.
    let snapshot_step = (record.until.abs() / 12.0).max(0.1);
    if !clusters.is_empty() {
        let mut next = 0.0;
        for f in frames {
            if f.t.abs() + 1e-9 < next {
                continue;
            }
            next = f.t.abs() + snapshot_step;
            let body = bodies_at(record, f.t);
            for members in clusters {
                if !members.iter().all(|&k| body[k] == body[members[0]]) {
                    continue;
                }
                let centres: Vec<Px> = members
                    .iter()
                    .map(|&k| v.px(xy(&f.states.pos[k])))
                    .collect();
                for (&k, &c) in members.iter().zip(&centres) {
                    canvas.ring(
                        c,
                        v.len(scene.balls[k].radius),
                        lighter(ball_colour(k), 0.55).to_rgba(),
                        1.0,
                    )?;
                }
                canvas.polyline(&centres, lighter(INK, 0.6).to_rgba(), 1.5)?;
            }
        }
    }
    Ok(())
}

/// The paths of the balls (in 2D) and of the centre of mass.
fn paths(canvas: &Canvas<'_>, record: &Record, l: &Layout, frames: &[super::lab::Frame]) -> Drawn {
    let v = &l.view;
    let scene = &record.scene;
    // Paths (on 1D screens the space-time diagram shows them).
    for k in (0..scene.balls.len()).filter(|_| l.spacetime.is_none()) {
        let path: Vec<Px> = frames.iter().map(|f| v.px(xy(&f.states.pos[k]))).collect();
        canvas.polyline(&path, ball_colour(k).mix(0.85), 2.5)?;
    }
    let com: Vec<Px> = frames
        .iter()
        .map(|f| v.px(xy(&quantities(scene, &f.states).com)))
        .collect();
    canvas.polyline(&com, COM.mix(0.55), 1.5)?;
    Ok(())
}

/// Collision markers, numbered as in the table.
fn markers(canvas: &Canvas<'_>, record: &Record, l: &Layout, t: f64) -> Drawn {
    let v = &l.view;
    let scene = &record.scene;
    // Collision markers, numbered as in the table.
    {
        for (n, instant) in record.instants.iter().enumerate() {
            if instant.t.abs() > t.abs() {
                break;
            }
            for c in &instant.collisions {
                if let Collision::BallBall { i, j, .. } = *c {
                    let (pi, pj) = (instant.after.pos[i], instant.after.pos[j]);
                    let (ri, rj) = (scene.balls[i].radius, scene.balls[j].radius);
                    let contact = pi + (pj - pi) * (ri / (ri + rj));
                    contact_marker(canvas, v.px(xy(&contact)), n + 1, 9.0)?;
                }
            }
        }
    }
    Ok(())
}

/// The balls now, with momentum (coloured) and velocity (dark) arrows, the clusters'
/// links, the centre of mass and the total momentum.
fn balls_now(
    canvas: &Canvas<'_>,
    record: &Record,
    l: &Layout,
    s: &carom::sim::BallStates<f64, 2>,
    clusters: &[Vec<usize>],
) -> Drawn {
    let v = &l.view;
    let scene = &record.scene;
    // The balls now, with momentum (coloured) and velocity (dark) arrows.
    for members in clusters {
        let centres: Vec<Px> = members.iter().map(|&k| v.px(xy(&s.pos[k]))).collect();
        canvas.polyline(&centres, INK.to_rgba(), 3.0)?;
    }
    for (k, b) in scene.balls.iter().enumerate() {
        let c = v.px(xy(&s.pos[k]));
        canvas.disk(
            c,
            v.len(b.radius),
            ball_colour(k).mix(0.92),
            darker(ball_colour(k), 0.35).to_rgba(),
            1.5,
        )?;
    }
    for members in clusters {
        let centres: Vec<Px> = members.iter().map(|&k| v.px(xy(&s.pos[k]))).collect();
        canvas.polyline(&centres, INK.mix(0.7), 2.0)?;
    }
    for (k, b) in scene.balls.iter().enumerate() {
        let c = v.px(xy(&s.pos[k]));
        let p = s.vel[k] * b.mass;
        canvas.arrow(
            c,
            v.px(xy(&(s.pos[k] + p * MOMENTUM_SCALE))),
            darker(ball_colour(k), 0.25).to_rgba(),
            7.0,
            20.0,
        )?;
        canvas.arrow(
            c,
            v.px(xy(&(s.pos[k] + s.vel[k] * VELOCITY_SCALE))),
            INK.to_rgba(),
            2.5,
            13.0,
        )?;
        canvas.text(&format!("{}", k + 1), c, 15.0, INK, Anchor::Centre)?;
    }
    // The centre of mass and the total momentum.
    let q = quantities(scene, s);
    let cm = v.px(xy(&q.com));
    canvas.arrow(
        cm,
        v.px(xy(&(q.com + q.momentum * MOMENTUM_SCALE))),
        TOTAL.mix(0.85),
        4.0,
        16.0,
    )?;
    canvas.disk(
        cm,
        6.0,
        RGBColor(255, 255, 255).to_rgba(),
        COM.to_rgba(),
        2.0,
    )?;
    canvas.polyline(
        &[(cm.0 - 4.0, cm.1 - 4.0), (cm.0 + 4.0, cm.1 + 4.0)],
        COM.to_rgba(),
        1.5,
    )?;
    canvas.polyline(
        &[(cm.0 - 4.0, cm.1 + 4.0), (cm.0 + 4.0, cm.1 - 4.0)],
        COM.to_rgba(),
        1.5,
    )?;
    Ok(())
}

/// The space-time diagram of a 1D screen: each ball's position (across, to the scale of
/// the play area above) against time (down), its band as wide as the ball.
fn spacetime(
    canvas: &Canvas<'_>,
    record: &Record,
    l: &Layout,
    upto: usize,
    top: f64,
    bottom: f64,
) -> Drawn {
    let scene = &record.scene;
    let span = record.until.abs();
    let y_of = |t: f64| top + (bottom - top) * t.abs() / span;
    let x_of = |x: f64| l.view.px((x, 0.0)).0;
    canvas.fill_rect((l.area_min.0, top), (l.area_max.0, bottom), AREA.to_rgba())?;
    let step = [0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0]
        .into_iter()
        .find(|s| span / s <= 10.0)
        .unwrap_or(100.0);
    let mut t = 0.0;
    while t <= span + 1e-9 {
        let y = y_of(t);
        canvas.polyline(&[(l.area_min.0, y), (l.area_max.0, y)], GRID.to_rgba(), 1.0)?;
        canvas.text(
            &format!("{:.1} s", t * record.sign()),
            (l.area_min.0 - 8.0, y),
            12.0,
            MUTED,
            Anchor::Right,
        )?;
        t += step;
    }
    let frames = &record.frames[..=upto];
    for (k, b) in scene.balls.iter().enumerate() {
        let mut band: Vec<Px> = frames
            .iter()
            .map(|f| (x_of(f.states.pos[k].x - b.radius), y_of(f.t)))
            .collect();
        band.extend(
            frames
                .iter()
                .rev()
                .map(|f| (x_of(f.states.pos[k].x + b.radius), y_of(f.t))),
        );
        canvas.polygon(&band, ball_colour(k).mix(0.18))?;
    }
    for k in 0..scene.balls.len() {
        let line: Vec<Px> = frames
            .iter()
            .map(|f| (x_of(f.states.pos[k].x), y_of(f.t)))
            .collect();
        canvas.polyline(&line, ball_colour(k).to_rgba(), 2.5)?;
    }
    let now = frames[frames.len() - 1].t;
    for (n, instant) in record.instants.iter().enumerate() {
        if instant.t.abs() > now.abs() {
            break;
        }
        for c in &instant.collisions {
            if let Collision::BallBall { i, j, .. } = *c {
                let (xi, xj) = (instant.after.pos[i].x, instant.after.pos[j].x);
                let (ri, rj) = (scene.balls[i].radius, scene.balls[j].radius);
                let p = (x_of(xi + (xj - xi) * (ri / (ri + rj))), y_of(instant.t));
                contact_marker(canvas, p, n + 1, 8.0)?;
            }
        }
    }
    canvas.stroke_rect(
        (l.area_min.0, top),
        (l.area_max.0, bottom),
        MUTED.to_rgba(),
        1.0,
    )?;
    canvas.text("time ↓   (each ball's band is as wide as the ball; ◆ collisions, numbered as in the table)", (l.area_min.0, top - 16.0), 13.0, MUTED, Anchor::Left)
}

fn legend(canvas: &Canvas<'_>, record: &Record, l: &Layout, t: f64) -> Drawn {
    let y0 = l.spacetime.map_or(l.area_max.1, |(_, bottom)| bottom) + 36.0;
    let x0 = 20.0;
    let arrow_px = l.view.len(VELOCITY_SCALE);
    // Row 1: the arrow scales and symbols.
    canvas.arrow((x0, y0), (x0 + arrow_px, y0), INK.to_rgba(), 2.5, 13.0)?;
    canvas.text(
        "velocity: 1 m/s",
        (x0 + arrow_px + 10.0, y0),
        14.0,
        INK,
        Anchor::Left,
    )?;
    let x1 = x0 + arrow_px + 150.0;
    let m_px = l.view.len(MOMENTUM_SCALE);
    canvas.arrow(
        (x1, y0),
        (x1 + m_px, y0),
        darker(ball_colour(1), 0.25).to_rgba(),
        7.0,
        20.0,
    )?;
    canvas.text(
        "momentum: 1 kg·m/s (in the ball's colour; red: the total, drawn from the centre of mass ⊗)",
        (x1 + m_px + 10.0, y0),
        14.0,
        INK,
        Anchor::Left,
    )?;
    let y1 = y0 + 30.0;
    canvas.polyline(&[(x0, y1), (x0 + 40.0, y1)], ball_colour(0).mix(0.85), 2.5)?;
    let path_label = if l.spacetime.is_some() {
        "a ball's position over time (below)"
    } else {
        "path of a ball's centre"
    };
    canvas.text(path_label, (x0 + 50.0, y1), 14.0, INK, Anchor::Left)?;
    let x2 = x0 + 330.0;
    canvas.polyline(&[(x2, y1), (x2 + 40.0, y1)], COM.mix(0.55), 1.5)?;
    canvas.text(
        "path of the centre of mass",
        (x2 + 50.0, y1),
        14.0,
        INK,
        Anchor::Left,
    )?;
    let x3 = x2 + 280.0;
    canvas.polygon(
        &[
            (x3, y1 - 5.0),
            (x3 + 5.0, y1),
            (x3, y1 + 5.0),
            (x3 - 5.0, y1),
        ],
        INK.to_rgba(),
    )?;
    canvas.text(
        "ball–ball contact, numbered as in the table",
        (x3 + 12.0, y1),
        14.0,
        INK,
        Anchor::Left,
    )?;
    let x4 = x3 + 340.0;
    canvas.disk(
        (x4, y1),
        8.0,
        lighter(ball_colour(0), 0.78).to_rgba(),
        lighter(ball_colour(0), 0.4).to_rgba(),
        1.0,
    )?;
    canvas.text("start (t = 0)", (x4 + 14.0, y1), 14.0, INK, Anchor::Left)?;
    legend_quantities(canvas, record, x0, y1 + 32.0, t)
}

/// The last rows of the legend: the quantities at the start and now.
fn legend_quantities(canvas: &Canvas<'_>, record: &Record, x0: f64, y2: f64, t: f64) -> Drawn {
    let scene = &record.scene;
    let q0 = quantities(scene, &record.frames[0].states);
    let q1 = quantities(scene, &record.frames[record.frames.len() - 1].states);
    canvas.text(
        &format!(
            "total momentum ({:+.3}, {:+.3}) → ({:+.3}, {:+.3}) kg·m/s    kinetic energy {:.4} → {:.4} J    angular momentum about 0: {:+.4} → {:+.4} kg·m²/s    (t = 0 → {t:.2} s)",
            q0.momentum.x + 0.0,
            q0.momentum.y + 0.0,
            q1.momentum.x + 0.0,
            q1.momentum.y + 0.0,
            q0.kinetic,
            q1.kinetic,
            q0.angular_momentum + 0.0,
            q1.angular_momentum + 0.0
        ),
        (x0, y2),
        14.0,
        INK,
        Anchor::Left,
    )?;
    let clusters = groups(&bodies_at(record, t));
    if let Some(members) = clusters.first() {
        let (_, lc, w) = cluster_spin(
            scene,
            &record.frames[record.frames.len() - 1].states,
            members,
        );
        let names: Vec<String> = members.iter().map(|k| (k + 1).to_string()).collect();
        let snapshot = (record.until.abs() / 12.0).max(0.1);
        canvas.text(
            &format!(
                "stuck cluster {{{}}}: spins at ω = {w:+.4} rad/s, angular momentum about its centre of mass {lc:+.5} kg·m²/s (faint: the cluster every {snapshot:.2} s)",
                names.join(",")
            ),
            (x0, y2 + 26.0),
            14.0,
            INK,
            Anchor::Left,
        )?;
    }
    Ok(())
}

/// Draws the play-area picture of the whole run into `dir`; returns its path.
///
/// # Errors
/// Drawing or writing fails.
pub(crate) fn picture(record: &Record, dir: &Path) -> Result<PathBuf, Box<dyn Error>> {
    let l = layout(record, 1500, true);
    let mut raster = Raster::new(l.width, l.height);
    raster.draw(|canvas| {
        play(
            canvas,
            record,
            &l,
            Layers {
                upto: record.frames.len() - 1,
                markers: true,
                start: true,
                legend: true,
            },
        )
    })?;
    let path = dir.join(format!("{}.png", case_name(record.case)));
    raster.save_png(&path)?;
    Ok(path)
}

/// Draws an animated GIF of `frames` frames into `dir`; returns its path.
///
/// # Errors
/// Drawing or writing fails.
pub(crate) fn animation(
    record: &Record,
    dir: &Path,
    frames: usize,
) -> Result<PathBuf, Box<dyn Error>> {
    let l = layout(record, 900, false);
    let path = dir.join(format!("{}.gif", case_name(record.case)));
    let span = record.until.abs();
    let delay_cs = ((span / frames as f64) * 100.0).round().clamp(2.0, 100.0) as u16;
    let mut gif = Animation::create(&path, l.width, l.height, delay_cs)?;
    let mut raster = Raster::new(l.width, l.height);
    let count = record.frames.len();
    for n in 0..frames {
        let target = span * (n as f64) / ((frames - 1).max(1) as f64);
        let upto = record
            .frames
            .iter()
            .rposition(|f| f.t.abs() <= target + 1e-9)
            .unwrap_or(0)
            .min(count - 1);
        raster.clear();
        raster.draw(|canvas| {
            play(
                canvas,
                record,
                &l,
                Layers {
                    upto,
                    markers: false,
                    start: false,
                    legend: false,
                },
            )
        })?;
        gif.push(&raster)?;
    }
    Ok(path)
}

/// The angular momentum about its own centre of mass of the first stuck cluster at the
/// end, over the frames where it is stuck.
fn cluster_angular_series(record: &Record) -> Vec<(f64, f64)> {
    let scene = &record.scene;
    let clusters = record.final_clusters();
    match clusters.first() {
        Some(members) => record
            .frames
            .iter()
            .filter(|f| {
                let b = bodies_at(record, f.t);
                members.iter().all(|&k| b[k] == b[members[0]])
            })
            .map(|f| (f.t, cluster_spin(scene, &f.states, members).1))
            .collect(),
        None => Vec::new(),
    }
}

/// Draws the quantities over time (momentum, kinetic energy, centre of mass, angular
/// momentum) into `dir`; returns its path.
///
/// # Errors
/// Drawing or writing fails.
pub(crate) fn quantities_chart(record: &Record, dir: &Path) -> Result<PathBuf, Box<dyn Error>> {
    let scene = &record.scene;
    let (width, height) = (1200u32, 1000u32);
    let mut raster = Raster::new(width, height);
    let t_end = record.until;
    let (t_lo, t_hi) = if t_end < 0.0 {
        (t_end, 0.0)
    } else {
        (0.0, t_end)
    };
    let series: Vec<(f64, super::lab::Quantities)> = record
        .frames
        .iter()
        .map(|f| (f.t, quantities(scene, &f.states)))
        .collect();
    let cluster_l = cluster_angular_series(record);
    raster.draw(|canvas| {
        canvas.text(
            &format!("{}: what the sim teaches, over time", title(record)),
            (20.0, 22.0),
            22.0,
            INK,
            Anchor::Left,
        )?;
        canvas.text(&settings(record), (20.0, 50.0), 14.0, MUTED, Anchor::Left)?;
        canvas.text(
            "vertical lines: grey a collision between balls, red a wall contact",
            (f64::from(width) - 20.0, 50.0),
            14.0,
            MUTED,
            Anchor::Right,
        )?;
        let area = canvas.area().margin(Canvas::scaled(70.0), 0, 0, 0);
        let panels = area.split_evenly((4, 1));
        let momentum: Vec<Series<'_>> = vec![
            (
                "P x",
                ball_colour(1),
                series.iter().map(|(t, q)| (*t, q.momentum.x)).collect(),
            ),
            (
                "P y",
                ball_colour(4),
                series.iter().map(|(t, q)| (*t, q.momentum.y)).collect(),
            ),
        ];
        let energy: Vec<Series<'_>> = vec![(
            "KE",
            ball_colour(2),
            series.iter().map(|(t, q)| (*t, q.kinetic)).collect(),
        )];
        let com: Vec<Series<'_>> = vec![
            (
                "CM x",
                ball_colour(1),
                series.iter().map(|(t, q)| (*t, q.com.x)).collect(),
            ),
            (
                "CM y",
                ball_colour(4),
                series.iter().map(|(t, q)| (*t, q.com.y)).collect(),
            ),
        ];
        let mut angular: Vec<Series<'_>> = vec![(
            "L about 0",
            ball_colour(3),
            series
                .iter()
                .map(|(t, q)| (*t, q.angular_momentum))
                .collect(),
        )];
        if !cluster_l.is_empty() {
            angular.push(("cluster L about its CM", ball_colour(0), cluster_l.clone()));
        }
        let specs: [(&str, &[Series<'_>]); 4] = [
            ("total momentum (kg·m/s)", &momentum),
            ("kinetic energy (J)", &energy),
            ("centre of mass (m)", &com),
            ("angular momentum (kg·m²/s)", &angular),
        ];
        let marks: Vec<(f64, RGBColor)> = record
            .instants
            .iter()
            .map(|i| {
                let colour = if i.has_wall() {
                    RGBColor(230, 120, 120)
                } else {
                    RGBColor(170, 170, 170)
                };
                (i.t, colour)
            })
            .collect();
        for (panel, (caption, lines)) in panels.iter().zip(specs) {
            line_chart(panel, caption, "t (s)", t_lo..t_hi, lines, &marks)?;
        }
        Ok(())
    })?;
    let path = dir.join(format!("{}-quantities.png", case_name(record.case)));
    raster.save_png(&path)?;
    Ok(path)
}
