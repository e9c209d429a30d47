//! A tour of carom's geometry on a small built-in scene: a floor, a tilted ramp and four
//! balls in 2D, then a sphere and two boxes in 3D. It prints, as tables, what each query
//! answers (overlap, signed distance, ball contacts, ray casts, the separating axis of two
//! boxes) and the bounding volumes fitted around the scene.
//!
//! Run: `cargo run --release --example geometry_tour`
//!
//! Conventions used below (the same in every carom query): shapes are closed and solid;
//! signed distances are negative in penetration; contact normals point from the other
//! shape towards the ball; ray times are in units of the ray's direction vector.

use std::error::Error;
use std::io::{self, Write};

use carom::d2::{Aabb, Ball, BoundingSphere, HalfSpace, Obb, Vector};
use carom::geometry::BoundingVolume;
use carom::geometry::fit::{min_area_rect, minimal_sphere, pca_obb, ritter_sphere};
use carom::geometry::query::{
    Distance, Overlap, PointQuery, Ray, RayCast, contact, overlaps, separation, signed_distance,
};
use carom::{d2, d3};

/// The tilt of the ramp, in degrees.
pub(crate) const RAMP_DEGREES: f64 = 20.0;

/// The built-in 2D scene.
pub(crate) struct Scene {
    /// The solid below `y = 0`.
    pub(crate) floor: HalfSpace,
    /// A plank tilted by [`RAMP_DEGREES`].
    pub(crate) ramp: Obb,
    /// Named balls: `a` sinks into the floor, `b` overlaps `a`, `c` rests on the ramp,
    /// `d` floats free.
    pub(crate) balls: Vec<(&'static str, Ball)>,
}

impl Scene {
    /// The default scene of the tour.
    ///
    /// # Errors
    /// Never for these constants; the constructors validate their input.
    pub(crate) fn default_scene() -> Result<Self, carom::InvalidValue> {
        let floor = HalfSpace::new(Vector::new(0.0, 1.0), Vector::new(0.0, 0.0))?;
        let ramp = Obb::from_angle(
            Vector::new(4.0, 1.0),
            Vector::new(1.5, 0.25),
            RAMP_DEGREES.to_radians(),
        )?;
        // Ball c sits on the ramp's top face: its centre is 0.25 + 0.3 along the face normal.
        let top_normal = ramp.axis(1);
        let balls = vec![
            ("a", Ball::new(Vector::new(0.0, 0.4), 0.5)?),
            ("b", Ball::new(Vector::new(0.8, 0.4), 0.5)?),
            ("c", Ball::new(ramp.center() + top_normal * 0.55, 0.3)?),
            ("d", Ball::new(Vector::new(2.0, 3.0), 0.4)?),
        ];
        Ok(Self { floor, ramp, balls })
    }
}

/// `x` with rounding noise below 5e-13 shown as zero (so no `-0.0000` in the tables).
fn tidy(x: f64) -> f64 {
    if x.abs() < 5e-13 { 0.0 } else { x }
}

fn v2(v: &Vector) -> String {
    format!("({:7.4}, {:7.4})", tidy(v.x), tidy(v.y))
}

fn v3(v: &d3::Vector) -> String {
    format!("({:7.4}, {:7.4}, {:7.4})", tidy(v.x), tidy(v.y), tidy(v.z))
}

fn yes(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// One row of the ball table: `ball` against `shape`. Any shape with point queries
/// (ball, AABB, OBB, half-space) works: that is all a ball contact needs.
fn ball_row<S>(
    out: &mut impl Write,
    name: &str,
    other: &str,
    ball: &Ball,
    shape: &S,
) -> io::Result<()>
where
    S: PointQuery<f64, 2>,
    Ball: Overlap<S> + Distance<f64, S>,
{
    let contact = match contact(ball, shape) {
        Some(c) => format!(
            "{:9.6}  {}  {}",
            tidy(c.depth),
            v2(&c.normal),
            v2(&c.point_on_shape)
        ),
        None => format!("{:>9}  {:>18}  {:>18}", "-", "-", "-"),
    };
    writeln!(
        out,
        "  {:<10} {:<8} {:<8} {:>12.6}  {contact}",
        name,
        other,
        yes(overlaps(ball, shape)),
        tidy(signed_distance(ball, shape))
    )
}

/// Prints the whole tour to `out`.
///
/// # Errors
/// Write errors of `out`, and (never for the built-in scene) invalid shape values.
pub(crate) fn tour(out: &mut impl Write) -> Result<(), Box<dyn Error>> {
    let scene = Scene::default_scene()?;
    writeln!(
        out,
        "carom geometry tour: a 2D scene in f64 (then a glance at 3D)\n"
    )?;
    shapes(out, &scene)?;
    ball_table(out, &scene)?;
    rays_and_boxes(out, &scene)?;
    fits(out, &scene)?;
    glance_at_3d(out)
}

/// The scene's shapes, one per line.
fn shapes(out: &mut impl Write, scene: &Scene) -> io::Result<()> {
    writeln!(out, "shapes")?;
    writeln!(
        out,
        "  floor      half-space  normal {}, offset {:.4} (the solid is y <= 0)",
        v2(&scene.floor.normal()),
        scene.floor.offset()
    )?;
    writeln!(
        out,
        "  ramp       obb         centre {}, half extents {}, tilted {RAMP_DEGREES}°",
        v2(&scene.ramp.center()),
        v2(&scene.ramp.half_extents())
    )?;
    for (name, ball) in &scene.balls {
        writeln!(
            out,
            "  {name:<10} ball        centre {}, radius {:.4}",
            v2(&ball.center()),
            ball.radius()
        )?;
    }

    Ok(())
}

/// Every ball against every other shape: overlap, signed distance, contact.
fn ball_table(out: &mut impl Write, scene: &Scene) -> io::Result<()> {
    writeln!(
        out,
        "\nballs against every other shape (contact normal points from the shape to the ball)"
    )?;
    writeln!(
        out,
        "  {:<10} {:<8} {:<8} {:>12}  {:>9}  {:>18}  {:>18}",
        "ball", "against", "overlaps", "signed dist", "depth", "normal", "point on shape"
    )?;
    for (name, ball) in &scene.balls {
        ball_row(out, name, "floor", ball, &scene.floor)?;
        ball_row(out, name, "ramp", ball, &scene.ramp)?;
        for (other_name, other) in &scene.balls {
            if other_name > name {
                ball_row(out, name, other_name, ball, other)?;
            }
        }
    }
    writeln!(
        out,
        "  ramp       floor    {:<8} {:>12.6}  (box against half-space: the lowest corner)",
        yes(overlaps(&scene.ramp, &scene.floor)),
        signed_distance(&scene.ramp, &scene.floor)
    )?;

    let (_, d) = scene.balls[3];
    let near = scene.ramp.closest_point(&d.center());
    writeln!(
        out,
        "\npoint query: the point of the ramp closest to d's centre is {}, {:.4} away",
        v2(&near),
        scene.ramp.distance_to_point(&d.center())
    )?;

    Ok(())
}

/// Ray casts from one point, and a box–box separating-axis test.
fn rays_and_boxes(out: &mut impl Write, scene: &Scene) -> Result<(), Box<dyn Error>> {
    writeln!(
        out,
        "\nrays from (-2, 2) (solid shapes: a ray starting inside hits at t = 0)"
    )?;
    writeln!(
        out,
        "  {:<18} {:<8} {:>9}  {:>18}  {:>18}",
        "direction", "target", "t", "hit point", "normal"
    )?;
    let origin = Vector::new(-2.0, 2.0);
    for direction in [
        Vector::new(1.0, -0.6),
        Vector::new(1.0, -0.2),
        Vector::new(4.0, 1.0),
    ] {
        let ray = Ray::new(origin, direction)?;
        let mut targets: Vec<(&str, Option<d2::RayHit>)> = vec![
            ("floor", scene.floor.cast_ray(&ray, f64::INFINITY)),
            ("ramp", scene.ramp.cast_ray(&ray, f64::INFINITY)),
        ];
        for (name, ball) in &scene.balls {
            targets.push((name, ball.cast_ray(&ray, f64::INFINITY)));
        }
        for (name, hit) in targets {
            let text = match hit {
                Some(h) => format!(
                    "{:9.4}  {}  {}",
                    h.toi,
                    v2(&ray.point_at(h.toi)),
                    v2(&h.normal)
                ),
                None => format!("{:>9}", "miss"),
            };
            writeln!(out, "  {:<18} {name:<8} {text}", v2(&direction))?;
        }
    }

    let crate_box = Obb::from_aabb(&Aabb::new(Vector::new(4.5, 0.0), Vector::new(5.5, 1.0))?);
    let s = separation(&crate_box, &scene.ramp);
    writeln!(
        out,
        "\nbox–box SAT: a crate [4.5, 5.5] × [0, 1] against the ramp: gap {:.4} along {} ({})",
        s.distance,
        v2(&s.axis),
        if s.distance < 0.0 {
            "penetration"
        } else {
            "apart"
        }
    )?;

    Ok(())
}

/// Bounding volumes fitted to points on the balls' rims.
fn fits(out: &mut impl Write, scene: &Scene) -> Result<(), Box<dyn Error>> {
    // Sixteen points on the rim of every ball.
    let points: Vec<Vector> = scene
        .balls
        .iter()
        .flat_map(|(_, b)| {
            (0..16).map(move |k| {
                let a = f64::from(k) * std::f64::consts::TAU / 16.0;
                b.center() + Vector::new(a.cos(), a.sin()) * b.radius()
            })
        })
        .collect();
    writeln!(
        out,
        "\nbounding volumes fitted to {} points on the balls' rims",
        points.len()
    )?;
    writeln!(
        out,
        "  {:<28} {:>18}  {:>18}  {:>9}",
        "method", "centre", "size", "area"
    )?;
    let aabb = Aabb::from_points(&points)?;
    writeln!(
        out,
        "  {:<28} {}  {}  {:9.4}",
        "AABB",
        v2(&aabb.center()),
        v2(&aabb.extents()),
        aabb.volume()
    )?;
    let sphere_row = |out: &mut dyn Write, name: &str, s: BoundingSphere| {
        writeln!(
            out,
            "  {:<28} {}  {:>18}  {:9.4}",
            name,
            v2(&s.center()),
            format!("radius {:.4}", s.radius()),
            s.volume()
        )
    };
    sphere_row(out, "circle, Ritter", ritter_sphere(&points)?)?;
    sphere_row(out, "circle, Welzl (minimal)", minimal_sphere(&points)?)?;
    for (name, obb) in [
        ("OBB, PCA", pca_obb(&points)?),
        ("rectangle, minimal area", min_area_rect(&points)?),
    ] {
        let size = obb.half_extents() * 2.0;
        writeln!(
            out,
            "  {:<28} {}  {}  {:9.4}",
            name,
            v2(&obb.center()),
            v2(&size),
            size.x * size.y
        )?;
    }

    Ok(())
}

/// 3D: a sphere against a turned cube, and two cubes edge to edge.
fn glance_at_3d(out: &mut impl Write) -> Result<(), Box<dyn Error>> {
    let cube = d3::Obb::from_axis_angle(
        d3::Vector::zeros(),
        d3::Vector::new(1.0, 1.0, 1.0),
        d3::Vector::new(0.0, 0.0, std::f64::consts::FRAC_PI_4),
    )?;
    let sphere = d3::Ball::new(d3::Vector::new(1.8, 0.0, 0.5), 0.5)?;
    writeln!(
        out,
        "\n3D: a cube turned 45° about z (its edge at x = √2 ≈ 1.4142) and a sphere at x = 1.8"
    )?;
    match contact(&sphere, &cube) {
        Some(c) => writeln!(
            out,
            "  contact: depth {:.6}, normal {}, point on cube {}",
            c.depth,
            v3(&c.normal),
            v3(&c.point_on_shape)
        )?,
        None => writeln!(out, "  no contact")?,
    }
    let other = d3::Obb::from_axis_angle(
        d3::Vector::new(2.0 * 2f64.sqrt() + 0.25, 0.0, 0.0),
        d3::Vector::new(1.0, 1.0, 1.0),
        d3::Vector::new(0.0, std::f64::consts::FRAC_PI_4, 0.0),
    )?;
    let s = separation(&cube, &other);
    writeln!(
        out,
        "  a second cube turned 45° about y, edge to edge: SAT gap {:.6} along {}, distance {:.6}",
        s.distance,
        v3(&s.axis),
        carom::geometry::query::distance(&cube, &other)
    )?;
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    tour(&mut io::stdout().lock())
}
