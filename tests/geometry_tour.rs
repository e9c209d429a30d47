//! The README's main job, `cargo run --release --example geometry_tour`: the tour runs on
//! its built-in scene and the numbers it prints are the closed forms of the scene's
//! geometry (computed here from the scene's constants, not by carom's queries).

#[allow(
    dead_code,
    reason = "the example's `main` is not called: the test calls `tour`"
)]
#[path = "../examples/geometry_tour.rs"]
mod example;

use example::{RAMP_DEGREES, Scene, tour};

/// The tour's output.
fn output() -> String {
    let mut out = Vec::new();
    tour(&mut out).expect("the tour runs on its built-in scene");
    String::from_utf8(out).expect("the tour prints UTF-8")
}

/// The whitespace-separated fields of the ball-table row `ball` × `against`.
fn row<'a>(text: &'a str, ball: &str, against: &str) -> Vec<&'a str> {
    text.lines()
        .map(|l| l.split_whitespace().collect::<Vec<_>>())
        .find(|f| f.len() > 4 && f[0] == ball && f[1] == against)
        .unwrap_or_else(|| panic!("no row {ball} × {against} in\n{text}"))
}

fn number(field: &str) -> f64 {
    field
        .parse()
        .unwrap_or_else(|_| panic!("{field} is not a number"))
}

#[test]
fn the_tour_prints_the_closed_form_contacts_of_its_scene() {
    let text = output();
    let scene = Scene::default_scene().unwrap();
    let ball = |name: &str| scene.balls.iter().find(|(n, _)| *n == name).unwrap().1;
    let (a, b, d) = (ball("a"), ball("b"), ball("d"));

    // a sinks r − y into the floor y = 0.
    let sink = a.radius() - a.center().y;
    let f = row(&text, "a", "floor");
    assert_eq!(f[2], "yes");
    assert!((number(f[3]) + sink).abs() < 1e-6, "{f:?}");
    assert!((number(f[4]) - sink).abs() < 1e-6, "{f:?}");

    // a and b overlap by r_a + r_b − |c_a − c_b|.
    let gap =
        ((a.center().x - b.center().x).powi(2) + (a.center().y - b.center().y).powi(2)).sqrt();
    let f = row(&text, "a", "b");
    assert!(
        (number(f[4]) - (a.radius() + b.radius() - gap)).abs() < 1e-6,
        "{f:?}"
    );

    // c rests on the ramp: touching, depth zero.
    let f = row(&text, "c", "ramp");
    assert_eq!(f[2], "yes");
    assert!(number(f[4]).abs() < 1e-6, "{f:?}");

    // d floats y − r above the floor.
    let f = row(&text, "d", "floor");
    assert_eq!((f[2], f[4]), ("no", "-"));
    assert!(
        (number(f[3]) - (d.center().y - d.radius())).abs() < 1e-6,
        "{f:?}"
    );

    // The ramp's lowest corner: centre height minus the projected half extents.
    let t = RAMP_DEGREES.to_radians();
    let (h, r) = (scene.ramp.half_extents(), scene.ramp.center());
    let lowest = r.y - h.x * t.sin() - h.y * t.cos();
    let ramp_line = text
        .lines()
        .find(|l| l.trim_start().starts_with("ramp       floor"))
        .unwrap();
    let f: Vec<_> = ramp_line.split_whitespace().collect();
    assert!((number(f[3]) - lowest).abs() < 1e-6, "{ramp_line}");
}

#[test]
fn the_tour_prints_rays_fits_and_the_3d_edge_gap() {
    let text = output();
    // The ray from (−2, 2) along (1, −0.6) reaches y = 0 at t = 2/0.6; the one along
    // (4, 1) rises and never meets the floor, but hits ball d at (2, 3).
    let hits: Vec<_> = text
        .lines()
        .filter(|l| l.contains("floor") && l.trim_start().starts_with('('))
        .collect();
    assert_eq!(hits.len(), 3, "{text}");
    let first: Vec<_> = hits[0]
        .split(')')
        .nth(1)
        .unwrap()
        .split_whitespace()
        .collect();
    assert!((number(first[1]) - 2.0 / 0.6).abs() < 1e-4, "{}", hits[0]);
    assert!(hits[2].contains("miss"), "{}", hits[2]);
    let towards_d = text
        .lines()
        .find(|l| l.trim_start().starts_with("( 4.0000,  1.0000) d"))
        .unwrap();
    assert!(!towards_d.contains("miss"), "{towards_d}");

    // The minimal circle is never larger than Ritter's.
    let radius = |method: &str| {
        let line = text.lines().find(|l| l.contains(method)).unwrap();
        let after = line.split("radius").nth(1).unwrap();
        number(after.split_whitespace().next().unwrap())
    };
    assert!(radius("Welzl") <= radius("Ritter"));

    // Two cubes turned 45° about z and about y, 0.25 apart edge to edge.
    let line = text.lines().find(|l| l.contains("edge to edge")).unwrap();
    let gap = number(
        line.split("SAT gap")
            .nth(1)
            .unwrap()
            .split_whitespace()
            .next()
            .unwrap(),
    );
    let dist = number(line.split("distance").nth(1).unwrap().trim());
    assert!(
        (gap - 0.25).abs() < 1e-6 && (dist - 0.25).abs() < 1e-6,
        "{line}"
    );

    // The sphere at x = 1.8 of radius 0.5 reaches past the cube's edge at x = √2.
    let line = text.lines().find(|l| l.contains("contact: depth")).unwrap();
    let depth = number(
        line.split("depth")
            .nth(1)
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .trim(),
    );
    assert!((depth - (0.5 - (1.8 - 2f64.sqrt()))).abs() < 1e-6, "{line}");
}
