//! The pictures of the rally: a top view and a side view (along the table's length) of
//! the table, the net, the walls, the paddle's swing and the balls' paths with their
//! contacts; each integrator's energy error over time; an animated GIF.

use std::error::Error;
use std::path::{Path, PathBuf};

use carom::sim::Collision;
use nalgebra::Vector3;
use plotters::prelude::*;

use super::picture::{
    Anchor, Animation, Canvas, INK, MUTED, Px, Raster, Series, View, ball_colour, darker, lighter,
    line_chart,
};
use super::rally::{BALL_RADIUS, Frame, NET_HEIGHT, Part, Rally, TABLE, energies, part};

const TABLE_BLUE: RGBColor = RGBColor(28, 78, 128);
const FLOOR: RGBColor = RGBColor(246, 248, 251);

type Drawn = Result<(), Box<dyn Error>>;

/// A projection of world points to the picture plane of a view.
type Project<'a> = &'a dyn Fn(&Vector3<f64>) -> (f64, f64);

/// Top view: world x, y.
fn top(p: &Vector3<f64>) -> (f64, f64) {
    (p.x, p.y)
}

fn panel(
    canvas: &Canvas<'_>,
    frame: &Frame,
    rally: &Rally,
    upto: usize,
    view: &View,
    project: Project<'_>,
    side: bool,
) -> Drawn {
    let (hx, hy, _) = TABLE;
    // The walls (top view) and the table top.
    if !side {
        for y in [hy + 1.4, -hy - 1.4] {
            let corners: Vec<Px> = [
                (-2.2, y - 0.05),
                (2.2, y - 0.05),
                (2.2, y + 0.05),
                (-2.2, y + 0.05),
            ]
            .iter()
            .map(|&(x, y)| view.px(project(&frame.world(Vector3::new(x, y, 0.3)))))
            .collect();
            canvas.polygon(&corners, lighter(MUTED, 0.5).to_rgba())?;
        }
    }
    let face: Vec<Px> = [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
        .iter()
        .map(|&(x, y)| view.px(project(&frame.world(Vector3::new(x, y, 0.0)))))
        .collect();
    if side {
        let a = view.px(project(&frame.world(Vector3::new(-hx, 0.0, 0.0))));
        let b = view.px(project(&frame.world(Vector3::new(hx, 0.0, -0.05))));
        canvas.fill_rect(a, b, TABLE_BLUE.to_rgba())?;
        // Legs.
        for x in [-hx + 0.2, hx - 0.2] {
            let top = view.px(project(&frame.world(Vector3::new(x, 0.0, -0.05))));
            let foot = view.px((project(&frame.world(Vector3::new(x, 0.0, 0.0))).0, 0.0));
            canvas.polyline(&[top, foot], MUTED.to_rgba(), 4.0)?;
        }
    } else {
        canvas.polygon(&face, TABLE_BLUE.to_rgba())?;
        let centre_line = [
            view.px(project(&frame.world(Vector3::new(-hx, 0.0, 0.0)))),
            view.px(project(&frame.world(Vector3::new(hx, 0.0, 0.0)))),
        ];
        canvas.polyline(&centre_line, RGBColor(255, 255, 255).mix(0.8), 1.0)?;
    }
    let mut closed = face.clone();
    closed.push(face[0]);
    if !side {
        canvas.polyline(&closed, RGBColor(255, 255, 255).to_rgba(), 2.0)?;
    }
    // The net.
    let net: Vec<Px> = if side {
        [(0.0, 0.0), (0.0, NET_HEIGHT)]
            .iter()
            .map(|&(x, z)| view.px(project(&frame.world(Vector3::new(x, 0.0, z)))))
            .collect()
    } else {
        [-hy - NET_HEIGHT, hy + NET_HEIGHT]
            .iter()
            .map(|&y| view.px(project(&frame.world(Vector3::new(0.0, y, NET_HEIGHT)))))
            .collect()
    };
    canvas.polyline(&net, INK.to_rgba(), 3.0)?;
    // The paddle's path and the blade at a few times.
    let path: Vec<Px> = rally.paddle[..=upto]
        .iter()
        .map(|p| view.px(project(p)))
        .collect();
    canvas.polyline(&path, RGBColor(200, 40, 40).mix(0.35), 2.0)?;
    let blade = |p: &Vector3<f64>| {
        let half = 0.08;
        let local_axis = if side {
            Vector3::new(0.0, 0.0, half)
        } else {
            Vector3::new(0.0, half, 0.0)
        };
        let d = frame.direction(local_axis);
        [view.px(project(&(p - d))), view.px(project(&(p + d)))]
    };
    let every = (rally.paddle.len() / 12).max(1);
    for (k, p) in rally.paddle[..=upto].iter().enumerate() {
        if k % every == 0 || k == upto {
            let colour = if k == upto {
                RGBColor(200, 40, 40).to_rgba()
            } else {
                RGBColor(200, 40, 40).mix(0.25)
            };
            canvas.polyline(&blade(p), colour, 5.0)?;
        }
    }
    balls(canvas, rally, upto, view, project)
}

/// The balls' paths, the contacts and the balls now.
fn balls(
    canvas: &Canvas<'_>,
    rally: &Rally,
    upto: usize,
    view: &View,
    project: Project<'_>,
) -> Drawn {
    for i in 0..rally.scene.balls.len() {
        let path: Vec<Px> = rally.frames[..=upto]
            .iter()
            .map(|(_, s)| view.px(project(&s.pos[i])))
            .collect();
        canvas.polyline(&path, ball_colour(i).mix(0.9), 2.0)?;
    }
    let t_now = rally.frames[upto].0;
    for c in rally.events.iter().filter(|c| c.time() <= t_now) {
        let step = ((c.time() / rally.dt).ceil() as usize).min(rally.frames.len() - 1);
        let (i, colour) = match *c {
            Collision::BallBall { i, .. } => (i, INK),
            Collision::BallBox { i, k, .. } if part(k) == Part::Paddle => {
                (i, RGBColor(200, 40, 40))
            }
            Collision::BallBox { i, .. } | Collision::BallBorder { i, .. } => {
                (i, darker(ball_colour(i), 0.3))
            }
        };
        let p = view.px(project(&rally.frames[step].1.pos[i]));
        canvas.ring(p, 5.0, colour.to_rgba(), 2.0)?;
    }
    for i in 0..rally.scene.balls.len() {
        let p = view.px(project(&rally.frames[upto].1.pos[i]));
        canvas.disk(
            p,
            view.len(BALL_RADIUS).max(4.0),
            ball_colour(i).to_rgba(),
            darker(ball_colour(i), 0.4).to_rgba(),
            1.0,
        )?;
    }
    Ok(())
}

/// Half the length of the side view: the room (±4 m) seen along the tilted table reaches
/// at most its diagonal.
const SIDE_REACH: f64 = 5.7;

/// The top and side views at frame `upto`.
fn views(canvas: &Canvas<'_>, frame: &Frame, rally: &Rally, upto: usize, width: f64) -> Drawn {
    let along = |p: &Vector3<f64>| (frame.local(p).x, p.z);
    let gap = 30.0;
    let half = (width - 3.0 * gap) / 2.0;
    let top_view = View::fit(
        (-4.0, -4.0),
        (4.0, 4.0),
        (gap, 90.0),
        (gap + half, 90.0 + half * 0.92),
    );
    // Along the table, the room's corners are up to 4√2 m from the centre.
    let side_view = View::fit(
        (-SIDE_REACH, 0.0),
        (SIDE_REACH, 2.0),
        (2.0 * gap + half, 90.0),
        (width - gap, 90.0 + half * 0.92),
    );
    for (view, side, label) in [
        (
            &top_view,
            false,
            "from above: the room (world x, y; 0.5 m grid)",
        ),
        (
            &side_view,
            true,
            "from the side (along the table's length, height above the floor; 0.5 m grid)",
        ),
    ] {
        let (lo, hi) = if side {
            ((-SIDE_REACH, 0.0), (SIDE_REACH, 2.0))
        } else {
            ((-4.0, -4.0), (4.0, 4.0))
        };
        canvas.fill_rect(
            view.px((lo.0, hi.1)),
            view.px((hi.0, lo.1)),
            FLOOR.to_rgba(),
        )?;
        let mut x = (lo.0 * 2.0f64).ceil() / 2.0;
        while x <= hi.0 {
            canvas.polyline(
                &[view.px((x, lo.1)), view.px((x, hi.1))],
                RGBColor(226, 231, 238).to_rgba(),
                1.0,
            )?;
            x += 0.5;
        }
        let mut y = (lo.1 * 2.0f64).ceil() / 2.0;
        while y <= hi.1 {
            canvas.polyline(
                &[view.px((lo.0, y)), view.px((hi.0, y))],
                RGBColor(226, 231, 238).to_rgba(),
                1.0,
            )?;
            y += 0.5;
        }
        let project: Project<'_> = if side { &along } else { &top };
        panel(canvas, frame, rally, upto, view, project, side)?;
        let corner = view.px((lo.0, hi.1));
        canvas.text(
            label,
            (corner.0, corner.1 - 12.0),
            14.0,
            MUTED,
            Anchor::Left,
        )?;
    }
    Ok(())
}

fn header(canvas: &Canvas<'_>, rally: &Rally, upto: usize, width: f64) -> Drawn {
    let settings = format!(
        "{} at step {} s; ○ contacts (red: paddle, black: ball–ball); red arc: the paddle's swing",
        rally.integrator, rally.dt
    );
    canvas.header(
        "Ping pong on carom's stepped engine: tilted table (OBB), net, side walls, swung paddle, 3 balls",
        &settings,
        rally.frames[upto].0,
        width,
    )
}

/// The top and side views of the whole rally; returns the picture's path.
///
/// # Errors
/// Drawing or writing fails.
pub(crate) fn trajectories(
    frame: &Frame,
    rally: &Rally,
    dir: &Path,
) -> Result<PathBuf, Box<dyn Error>> {
    let (w, h) = (1600u32, 860u32);
    let mut raster = Raster::new(w, h);
    let upto = rally.frames.len() - 1;
    raster.draw(|canvas| {
        header(canvas, rally, upto, f64::from(w))?;
        views(canvas, frame, rally, upto, f64::from(w))?;
        let y = f64::from(h) - 24.0;
        let mut x = 20.0;
        for i in 0..rally.scene.balls.len() {
            canvas.disk(
                (x + 6.0, y),
                6.0,
                ball_colour(i).to_rgba(),
                darker(ball_colour(i), 0.4).to_rgba(),
                1.0,
            )?;
            let label = match i {
                0 => "ball 1: served, returned by the paddle",
                1 => "ball 2",
                _ => "ball 3 (2 and 3 meet above the net)",
            };
            canvas.text(label, (x + 18.0, y), 14.0, INK, Anchor::Left)?;
            x += 330.0;
        }
        Ok(())
    })?;
    let path = dir.join("ping_pong.png");
    raster.save_png(&path)?;
    Ok(path)
}

/// Each integrator's energy error against the reference over time; returns the path.
///
/// # Errors
/// Drawing or writing fails.
pub(crate) fn energy_chart(
    reference: &Rally,
    rallies: &[Rally],
    dir: &Path,
) -> Result<PathBuf, Box<dyn Error>> {
    let (w, h) = (1200u32, 800u32);
    let mut raster = Raster::new(w, h);
    let e_ref = energies(reference);
    let e0 = e_ref[0].1;
    let at = |t: f64| e_ref[((t / reference.dt).round() as usize).min(e_ref.len() - 1)].1;
    let until = e_ref[e_ref.len() - 1].0;
    raster.draw(|canvas| {
        canvas.text(
            "Ping pong: energy of the balls, and each integrator's error",
            (20.0, 22.0),
            22.0,
            INK,
            Anchor::Left,
        )?;
        let area = canvas.area().margin(Canvas::scaled(40.0), 0, 0, 0);
        let panels = area.split_evenly((2, 1));
        let total: Vec<Series<'_>> = vec![("exact, reference", INK, e_ref.clone())];
        let marks: Vec<(f64, RGBColor)> = reference
            .events
            .iter()
            .filter(|c| matches!(c, Collision::BallBox { k, .. } if part(*k) == Part::Paddle))
            .map(|c| (c.time(), RGBColor(200, 40, 40)))
            .collect();
        line_chart(
            &panels[0],
            "kinetic + potential energy (J); red line: the paddle hit",
            "t (s)",
            0.0..until,
            &total,
            &marks,
        )?;
        let errors: Vec<Series<'_>> = rallies
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let name: &'static str = r.integrator.name();
                let pts = energies(r)
                    .into_iter()
                    .map(|(t, e)| (t, (e - at(t)) / e0))
                    .collect();
                (name, ball_colour(k + 1), pts)
            })
            .collect();
        let step = rallies.first().map_or(0.0, |r| r.dt);
        line_chart(
            &panels[1],
            &format!("(E − E_ref) / E(0) at step {step:.4} s"),
            "t (s)",
            0.0..until,
            &errors,
            &marks,
        )
    })?;
    let path = dir.join("ping_pong-energy.png");
    raster.save_png(&path)?;
    Ok(path)
}

/// An animated GIF of the reference rally; returns its path.
///
/// # Errors
/// Drawing or writing fails.
pub(crate) fn animation(
    frame: &Frame,
    rally: &Rally,
    dir: &Path,
    frames: usize,
) -> Result<PathBuf, Box<dyn Error>> {
    let (w, h) = (1000u32, 540u32);
    let path = dir.join("ping_pong.gif");
    let until = rally.frames[rally.frames.len() - 1].0;
    let delay = ((until / frames as f64) * 100.0).round().clamp(2.0, 100.0) as u16;
    let mut gif = Animation::create(&path, w, h, delay)?;
    let mut raster = Raster::new(w, h);
    for n in 0..frames {
        let t = until * n as f64 / (frames - 1) as f64;
        let upto = ((t / rally.dt).round() as usize).min(rally.frames.len() - 1);
        raster.clear();
        raster.draw(|canvas| {
            canvas.text(
                &format!("t = {:.2} s", rally.frames[upto].0),
                (f64::from(w) - 20.0, 22.0),
                18.0,
                INK,
                Anchor::Right,
            )?;
            views(canvas, frame, rally, upto, f64::from(w))
        })?;
        gif.push(&raster)?;
    }
    Ok(path)
}
