//! The printed part of the example: the set-up, the table of collisions with momenta
//! before and after, the quantities over time, and what is conserved, shown with numbers.

use std::fmt::Write as _;
use std::io::{self, Write};

use carom::sim::Collision;
use carom::sim::scene::Inelastic;
use carom::sim::scenes::collision_lab::{DENSITY, Screen};
use nalgebra::Vector2;

use super::lab::{
    Case, Frame, Instant, Record, cluster_spin, is_1d, momentum_of, quantities, screen_of,
    wall_name,
};

/// A momentum or velocity: `(+0.500, -0.150)`, or `+0.500` on a 1D screen.
pub(crate) fn vector(v: &Vector2<f64>, one_d: bool) -> String {
    // Values that round to zero print as +0.0000, whatever their sign.
    let c = |x: f64| if x.abs() < 0.5e-4 { 0.0 } else { x };
    if one_d {
        format!("{:+.4}", c(v.x))
    } else {
        format!("({:+.4}, {:+.4})", c(v.x), c(v.y))
    }
}

/// The title line of a run.
pub(crate) fn title(record: &Record) -> String {
    let screen = match record.case {
        Case::Screen(Screen::Intro) => "Intro".to_owned(),
        Case::Screen(Screen::Explore1d) => "Explore 1D".to_owned(),
        Case::Screen(Screen::Explore2d) => "Explore 2D".to_owned(),
        Case::Screen(Screen::Inelastic(p)) => format!("Inelastic, {}", preset_name(p)),
        Case::SpinningClusterWall => "a spinning stuck cluster at the wall".to_owned(),
    };
    format!("Collision Lab: {screen}")
}

fn preset_name(p: carom::sim::scenes::collision_lab::InelasticPreset) -> &'static str {
    use carom::sim::scenes::collision_lab::InelasticPreset as P;
    match p {
        P::HeadOn => "head-on",
        P::CrissCross => "criss-cross",
        P::Glancing => "glancing",
    }
}

/// The settings line of a run: balls, elasticity, border, sizes, time span.
pub(crate) fn settings(record: &Record) -> String {
    let s = &record.scene;
    let elasticity = s.world.restitution * 100.0;
    let inelastic = if elasticity == 0.0 {
        match s.world.inelastic {
            Inelastic::Stick => " (stick)",
            Inelastic::Slide => " (slide)",
        }
    } else {
        ""
    };
    let border = if s.world.border.is_some() {
        "reflecting border"
    } else {
        "no border"
    };
    let size = if record.options.constant_size {
        "constant radius 0.15 m".to_owned()
    } else {
        format!("radius from mass at {DENSITY} kg/m³")
    };
    let time = if record.until < 0.0 {
        format!("t = 0 → {} s (backwards)", record.until)
    } else {
        format!("t = 0 → {} s", record.until)
    };
    format!(
        "{} balls, elasticity {elasticity:.0} %{inelastic}, {border}, {size}, {time}",
        s.balls.len()
    )
}

/// A body's name: `ball 2` or `cluster {1,2}` (balls numbered from 1 as in the sim).
fn body_name(body: &[usize], root: usize) -> String {
    let members: Vec<usize> = (0..body.len()).filter(|&k| body[k] == root).collect();
    if members.len() == 1 {
        format!("ball {}", root + 1)
    } else {
        let names: Vec<String> = members.iter().map(|k| (k + 1).to_string()).collect();
        format!("cluster {{{}}}", names.join(","))
    }
}

/// What collided at an instant, in words.
fn describe(record: &Record, instant: &Instant, c: &Collision<f64>) -> String {
    let b = &instant.body_before;
    match *c {
        Collision::BallBall { i, j, .. } => {
            let stuck = instant.body_after[i] == instant.body_after[j];
            format!(
                "{} + {}{}",
                body_name(b, b[i]),
                body_name(b, b[j]),
                if stuck { " (stick)" } else { "" }
            )
        }
        Collision::BallBorder { i, .. } => format!(
            "{} + {}",
            body_name(b, b[i]),
            wall_name(&record.scene, &instant.after, i)
        ),
        Collision::BallBox { i, k, .. } => format!("{} + box {k}", body_name(b, b[i])),
    }
}

/// The bodies (roots before the instant) that took part in an instant, in order.
fn involved(instant: &Instant) -> Vec<usize> {
    let mut roots = Vec::new();
    for c in &instant.collisions {
        let balls = match *c {
            Collision::BallBall { i, j, .. } => vec![i, j],
            Collision::BallBorder { i, .. } | Collision::BallBox { i, .. } => vec![i],
        };
        for k in balls {
            let r = instant.body_before[k];
            if !roots.contains(&r) {
                roots.push(r);
            }
        }
    }
    roots
}

/// `1 wall contact`, `3 wall contacts`.
fn plural(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// The members of body `root` in a body labelling.
fn members(body: &[usize], root: usize) -> Vec<usize> {
    (0..body.len()).filter(|&k| body[k] == root).collect()
}

/// Prints the whole report.
///
/// # Errors
/// Writing fails.
pub(crate) fn print(record: &Record, every: f64, out: &mut dyn Write) -> io::Result<()> {
    writeln!(out, "{}", title(record))?;
    writeln!(out, "{}", settings(record))?;
    writeln!(out, "engine: {}", record.pipeline.join(", "))?;
    writeln!(out)?;
    print_balls(record, out)?;
    print_collisions(record, out)?;
    print_quantities(record, every, out)?;
    print_conservation(record, out)
}

fn print_balls(record: &Record, out: &mut dyn Write) -> io::Result<()> {
    let one_d = is_1d(record.case);
    writeln!(out, "Balls at t = 0")?;
    writeln!(
        out,
        "  ball  mass (kg)  radius (m)  position (m)        velocity (m/s)"
    )?;
    for (k, b) in record.scene.balls.iter().enumerate() {
        writeln!(
            out,
            "  {:<4}  {:<9.3}  {:<10.4}  {:<18}  {}",
            k + 1,
            b.mass,
            b.radius,
            vector(&b.pos, one_d),
            vector(&b.vel, one_d)
        )?;
    }
    writeln!(out)
}

fn print_collisions(record: &Record, out: &mut dyn Write) -> io::Result<()> {
    let one_d = is_1d(record.case);
    let scene = &record.scene;
    writeln!(
        out,
        "Collisions ({} ball–ball, {} ball–wall); momenta p in kg·m/s, just before and just after",
        record.counters.ball_ball, record.counters.ball_border
    )?;
    if record.instants.is_empty() {
        writeln!(out, "  (none before t = {} s)", record.until)?;
        return writeln!(out);
    }
    writeln!(
        out,
        "  {:>3}  {:>8}  {:<34}  {:<16}  {:<20}  {:<20}",
        "#", "t (s)", "collision", "body", "p before", "p after"
    )?;
    for (n, instant) in record.instants.iter().enumerate() {
        let what: Vec<String> = instant
            .collisions
            .iter()
            .map(|c| describe(record, instant, c))
            .collect();
        let roots = involved(instant);
        let mut total_before = Vector2::zeros();
        let mut total_after = Vector2::zeros();
        for (row, &root) in roots.iter().enumerate() {
            let m = members(&instant.body_before, root);
            let p0 = momentum_of(scene, &instant.before, &m);
            let p1 = momentum_of(scene, &instant.after, &m);
            total_before += p0;
            total_after += p1;
            let (num, time, label) = if row == 0 {
                (
                    (n + 1).to_string(),
                    format!("{:.4}", instant.t),
                    what.join("; "),
                )
            } else {
                (String::new(), String::new(), String::new())
            };
            writeln!(
                out,
                "  {num:>3}  {time:>8}  {label:<34}  {:<16}  {:<20}  {:<20}",
                body_name(&instant.body_before, root),
                vector(&p0, one_d),
                vector(&p1, one_d)
            )?;
        }
        let change = (total_after - total_before).norm();
        let note = if instant.has_wall() {
            format!(
                "the wall's impulse: {}",
                vector(&(total_after - total_before), one_d)
            )
        } else {
            format!("conserved: |Δp| = {change:.1e}")
        };
        writeln!(
            out,
            "  {:>3}  {:>8}  {:<34}  {:<16}  {:<20}  {:<20}  {note}",
            "",
            "",
            "",
            "total",
            vector(&total_before, one_d),
            vector(&total_after, one_d)
        )?;
        let k0 = quantities(scene, &instant.before).kinetic;
        let k1 = quantities(scene, &instant.after).kinetic;
        let ke_note = if (k1 - k0).abs() <= 1e-12 * k0.max(1e-300) {
            "kept".to_owned()
        } else {
            format!("{:+.4} J ({:+.1} %)", k1 - k0, 100.0 * (k1 - k0) / k0)
        };
        writeln!(
            out,
            "  {:>3}  {:>8}  {:<34}  {:<16}  {:<20}  {:<20}  {ke_note}",
            "",
            "",
            "",
            "kinetic energy J",
            format!("{k0:.6}"),
            format!("{k1:.6}")
        )?;
    }
    writeln!(out)
}

/// The frames nearest to multiples of `every` (and the last frame).
pub(crate) fn sampled(frames: &[Frame], every: f64) -> Vec<&Frame> {
    let mut out: Vec<&Frame> = Vec::new();
    let mut next = 0.0;
    for (k, f) in frames.iter().enumerate() {
        let last = k + 1 == frames.len();
        if f.t.abs() + 1e-9 >= next || last {
            if out.last().is_none_or(|p| !std::ptr::eq(*p, f)) {
                out.push(f);
            }
            while next <= f.t.abs() + 1e-9 {
                next += every;
            }
        }
    }
    out
}

fn print_quantities(record: &Record, every: f64, out: &mut dyn Write) -> io::Result<()> {
    let one_d = is_1d(record.case);
    let scene = &record.scene;
    let clusters = record.final_clusters();
    writeln!(
        out,
        "The system over time (P total momentum, KE kinetic energy, CM centre of mass, L angular momentum about the origin)"
    )?;
    let (p_head, cm_head) = if one_d {
        ("P (kg·m/s)", "CM x (m)")
    } else {
        ("P (kg·m/s)", "CM (m)")
    };
    let mut header = format!(
        "  {:>8}  {:<20}  {:>10}  {:<20}  {:>12}",
        "t (s)", p_head, "KE (J)", cm_head, "L (kg·m²/s)"
    );
    for c in &clusters {
        let names: Vec<String> = c.iter().map(|k| (k + 1).to_string()).collect();
        let label = format!("cluster {{{}}} L_cm, ω", names.join(","));
        let _ = write!(header, "  {label:>24}");
    }
    writeln!(out, "{header}")?;
    for f in sampled(&record.frames, every) {
        let q = quantities(scene, &f.states);
        let mut line = format!(
            "  {:>8.3}  {:<20}  {:>10.6}  {:<20}  {:>12.6}",
            f.t,
            vector(&q.momentum, one_d),
            q.kinetic,
            vector(&q.com, one_d),
            q.angular_momentum
        );
        for c in &clusters {
            let stuck = bodies_at(record, f.t)
                .iter()
                .filter(|&&b| b == c[0])
                .count()
                == c.len();
            if stuck {
                let (_, l, w) = cluster_spin(scene, &f.states, c);
                let _ = write!(line, "  {l:>14.6} {w:>+9.4}");
            } else {
                let _ = write!(line, "  {:>24}", "(not yet stuck)");
            }
        }
        writeln!(out, "{line}")?;
    }
    writeln!(out)
}

/// The body labels in force at time `t`.
pub(crate) fn bodies_at(record: &Record, t: f64) -> Vec<usize> {
    let mut body: Vec<usize> = (0..record.scene.balls.len()).collect();
    for i in &record.instants {
        if i.t.abs() <= t.abs() {
            body.clone_from(&i.body_after);
        }
    }
    body
}

/// The conservation facts of a run, measured.
#[derive(Clone, Debug, Default)]
pub(crate) struct Conservation {
    /// Ball–ball instants (no wall).
    pub(crate) ball_ball_instants: usize,
    /// Instants with a wall.
    pub(crate) wall_instants: usize,
    /// Largest change of total momentum across a ball–ball instant.
    pub(crate) max_momentum_change: f64,
    /// Largest change of angular momentum about the origin across a ball–ball instant.
    pub(crate) max_angular_change: f64,
    /// Largest relative change of kinetic energy across a ball–ball instant.
    pub(crate) max_energy_change: f64,
    /// Kinetic energy at the start and the end.
    pub(crate) energy: (f64, f64),
    /// Largest distance of the centre of mass from its straight line before the first wall.
    pub(crate) com_deviation: f64,
    /// When the first wall contact happened (or the end).
    pub(crate) first_wall: f64,
    /// Per final cluster: the largest change of its angular momentum about its own centre
    /// of mass between consecutive frames without a wall contact, and its value at the end.
    pub(crate) cluster_l: Vec<(Vec<usize>, f64, f64)>,
}

/// Measures what is conserved in a run.
pub(crate) fn conservation(record: &Record) -> Conservation {
    let scene = &record.scene;
    let mut c = Conservation::default();
    for i in &record.instants {
        let (q0, q1) = (quantities(scene, &i.before), quantities(scene, &i.after));
        if i.has_wall() {
            c.wall_instants += 1;
        } else {
            c.ball_ball_instants += 1;
            c.max_momentum_change = c
                .max_momentum_change
                .max((q1.momentum - q0.momentum).norm());
            c.max_angular_change = c
                .max_angular_change
                .max((q1.angular_momentum - q0.angular_momentum).abs());
            c.max_energy_change = c
                .max_energy_change
                .max(((q1.kinetic - q0.kinetic) / q0.kinetic).abs());
        }
    }
    let first = &record.frames[0];
    let last = &record.frames[record.frames.len() - 1];
    let q_first = quantities(scene, &first.states);
    c.energy = (q_first.kinetic, quantities(scene, &last.states).kinetic);
    c.first_wall = record
        .instants
        .iter()
        .find(|i| i.has_wall())
        .map_or(record.until, |i| i.t);
    for f in &record.frames {
        if f.t.abs() > c.first_wall.abs() {
            break;
        }
        let q = quantities(scene, &f.states);
        let line = q_first.com + q_first.com_velocity * f.t;
        c.com_deviation = c.com_deviation.max((q.com - line).norm());
    }
    for members in record.final_clusters() {
        let mut max_change: f64 = 0.0;
        let mut previous: Option<f64> = None;
        let mut wall_index = 0;
        let walls: Vec<f64> = record
            .instants
            .iter()
            .filter(|i| {
                i.collisions.iter().any(|col| match *col {
                    Collision::BallBorder { i: b, .. } | Collision::BallBox { i: b, .. } => {
                        members.contains(&b)
                    }
                    Collision::BallBall { i: a, j: b, .. } => {
                        members.contains(&a) || members.contains(&b)
                    }
                })
            })
            .map(|i| i.t)
            .collect();
        let mut last_l = 0.0;
        for f in &record.frames {
            let body = bodies_at(record, f.t);
            let stuck = members.iter().all(|&k| body[k] == body[members[0]]);
            if !stuck {
                previous = None;
                continue;
            }
            // A contact of the cluster between two frames changes its L: start again.
            let mut crossed = false;
            while wall_index < walls.len() && walls[wall_index].abs() <= f.t.abs() {
                wall_index += 1;
                crossed = true;
            }
            let (_, l, _) = cluster_spin(scene, &f.states, &members);
            if let (Some(p), false) = (previous, crossed) {
                max_change = max_change.max((l - p).abs());
            }
            previous = Some(l);
            last_l = l;
        }
        c.cluster_l.push((members, max_change, last_l));
    }
    c
}

fn print_conservation(record: &Record, out: &mut dyn Write) -> io::Result<()> {
    let c = conservation(record);
    let e = record.scene.world.restitution;
    let walls = record.scene.world.border.is_some();
    writeln!(out, "What is conserved")?;
    writeln!(
        out,
        "  momentum:          conserved in every collision between balls: largest change of the total over {}: {:.1e} kg·m/s.",
        plural(c.ball_ball_instants, "such instant", "such instants"),
        c.max_momentum_change
    )?;
    if walls && c.wall_instants > 0 {
        writeln!(
            out,
            "                     not conserved at the walls: the border pushes back ({} changed the total).",
            plural(c.wall_instants, "wall contact", "wall contacts")
        )?;
    }
    if e == 1.0 {
        writeln!(
            out,
            "  kinetic energy:    conserved (elasticity 100 %): {:.9} J at the start, {:.9} J at the end; largest relative change at a collision {:.1e}.",
            c.energy.0, c.energy.1, c.max_energy_change
        )?;
    } else {
        writeln!(
            out,
            "  kinetic energy:    not conserved at elasticity {:.0} %: {:.6} J at the start, {:.6} J at the end ({:.1} % lost in collisions between balls).",
            e * 100.0,
            c.energy.0,
            c.energy.1,
            100.0 * (c.energy.0 - c.energy.1) / c.energy.0
        )?;
    }
    writeln!(
        out,
        "  centre of mass:    moves in a straight line at constant velocity until the first wall contact (t = {:.4} s): largest deviation {:.1e} m.",
        c.first_wall, c.com_deviation
    )?;
    writeln!(
        out,
        "  angular momentum:  about the origin, conserved in every collision between balls (largest change {:.1e} kg·m²/s){}.",
        c.max_angular_change,
        if walls && c.wall_instants > 0 {
            "; walls change it"
        } else {
            ""
        }
    )?;
    for (members, change, l) in &c.cluster_l {
        let names: Vec<String> = members.iter().map(|k| (k + 1).to_string()).collect();
        writeln!(
            out,
            "  stuck cluster {{{}}}: spins rigidly; its angular momentum about its own centre of mass is {l:.6} kg·m²/s, constant between contacts (largest change {change:.1e}).",
            names.join(",")
        )?;
    }
    if matches!(screen_of(record.case), Screen::Inelastic(_)) && record.final_clusters().is_empty()
    {
        writeln!(
            out,
            "  (no stuck cluster: with \"slide\", elasticity 0 % removes the approach velocity and the balls slide on)"
        )?;
    }
    writeln!(out)
}

/// How far any ball reaches past the play area's walls in a run: the largest
/// `(centre + radius) − wall` over every frame, ball and wall (negative: always inside).
pub(crate) fn deepest_past_walls(record: &Record) -> f64 {
    let area = carom::sim::scenes::collision_lab::play_area(screen_of(record.case));
    let (min, max) = (area.min(), area.max());
    let mut deepest = f64::NEG_INFINITY;
    for f in &record.frames {
        for (k, b) in record.scene.balls.iter().enumerate() {
            let p = f.states.pos[k];
            let r = b.radius;
            deepest = deepest
                .max(p.x + r - max.x)
                .max(min.x - (p.x - r))
                .max(p.y + r - max.y)
                .max(min.y - (p.y - r));
        }
    }
    deepest
}

/// The section of `--case spinning-cluster-wall`: the exact wall contact of a purely
/// spinning cluster, and how far it would pass through the wall without one.
///
/// # Errors
/// Writing fails.
pub(crate) fn print_gap(record: &Record, free: &Record, out: &mut dyn Write) -> io::Result<()> {
    let scene = &record.scene;
    writeln!(out, "A known gap of PhET's engine, handled")?;
    writeln!(
        out,
        "  PhET's engine lets a stuck cluster that only spins pass through a wall, and finds cluster–wall contacts by bisection"
    )?;
    writeln!(
        out,
        "  on a sampled grid, which can miss a contact. carom predicts them by conservative advancement with a rigorous speed bound."
    )?;
    let Some(stick) = record
        .instants
        .iter()
        .find(|i| i.body_after.iter().all(|&b| b == 0) && !i.has_wall())
    else {
        return writeln!(
            out,
            "  (the balls did not stick before t = {} s)\n",
            record.until
        );
    };
    let all: Vec<usize> = (0..scene.balls.len()).collect();
    let (_, l, w) = cluster_spin(scene, &stick.after, &all);
    writeln!(
        out,
        "  t = {:.4} s: the balls stick; the cluster's momentum is {} kg·m/s, so it does not move: it only spins, ω = {w:+.4} rad/s (L = {l:+.6} kg·m²/s).",
        stick.t,
        vector(&momentum_of(scene, &stick.after, &all), false)
    )?;
    for i in record.instants.iter().filter(|i| i.has_wall()) {
        let p = momentum_of(scene, &i.after, &all);
        let (_, l1, w1) = cluster_spin(scene, &i.after, &all);
        let ball = i
            .collisions
            .iter()
            .find_map(|c| match *c {
                Collision::BallBorder { i, .. } => Some(i),
                _ => None,
            })
            .unwrap_or(0);
        writeln!(
            out,
            "  t = {:.4} s: ball {} touches the {}; the wall's impulse gives the cluster momentum {} kg·m/s and ω = {w1:+.4} rad/s (L = {l1:+.6}).",
            i.t,
            ball + 1,
            wall_name(scene, &i.after, ball),
            vector(&p, false)
        )?;
    }
    let deepest = deepest_past_walls(record);
    writeln!(
        out,
        "  Over the whole run, sampled every {:.1} ms, no ball ever enters a wall: the deepest reach past a wall is {:.2e} m (≤ 0: inside).",
        (record.frames[1].t - record.frames[0].t).abs() * 1e3,
        deepest
    )?;
    writeln!(
        out,
        "  The same cluster with the border off reaches {:.1} cm past the right wall line: that is how far it would pass through.",
        deepest_past_walls(free) * 100.0
    )?;
    writeln!(out)
}
