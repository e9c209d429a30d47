//! The scene-file contract: what loads, and the one-line errors for what does not.

use carom_sim::scene::{Inelastic, LoadedScene, parse_scene};

const EXPLORE_2D: &str = r#"
dim = 2
name = "explore-2d"

[world]
gravity = [0.0, -9.81]
restitution = 1.0
inelastic = "slide"
friction = 0.0
drag = 0.0

[world.border]
min = [-2.0, -1.0]
max = [2.0, 1.0]
restitution = 1.0
periodic = false

[[balls]]
pos = [-1.0, 0.0]
vel = [1.0, 0.0]
radius = 0.15
mass = 0.5
restitution = 0.9

[[balls]]
pos = [0.5, 0.0]
radius = 0.15
mass = 1

[[boxes]]
center = [0.0, -0.5]
half_extents = [1.0, 0.05]
angle = 0.0
vel = [0.0, 0.0]
restitution = 1.0
"#;

fn error(text: &str) -> String {
    parse_scene(text)
        .expect_err("the scene must be rejected")
        .to_string()
}

#[test]
fn the_contract_example_loads_with_every_key() {
    let LoadedScene::D2(s) = parse_scene(EXPLORE_2D).unwrap() else {
        panic!("dim 2")
    };
    assert_eq!(s.name.as_deref(), Some("explore-2d"));
    assert_eq!(s.world.gravity.y, -9.81);
    assert_eq!(s.world.inelastic, Inelastic::Slide);
    assert_eq!(s.balls.len(), 2);
    assert_eq!(s.balls[1].vel.norm(), 0.0, "vel defaults to zero");
    assert_eq!(s.balls[1].mass, 1.0, "integers are accepted as numbers");
    assert_eq!(
        s.pair_restitution(0, 1),
        0.9,
        "a pair uses the minimum restitution"
    );
    assert_eq!(s.boxes[0].shape.half_extents().x, 1.0);
}

#[test]
fn defaults_fill_an_almost_empty_file() {
    let LoadedScene::D3(s) = parse_scene("dim = 3").unwrap() else {
        panic!("dim 3")
    };
    assert_eq!(s.world.restitution, 1.0);
    assert!(s.world.border.is_none() && s.balls.is_empty() && s.boxes.is_empty());
}

#[test]
fn unknown_keys_are_errors_naming_the_entry() {
    let e = error("dim = 2\n[[balls]]\npos = [0.0, 0.0]\nradiu = 1.0\nmass = 1.0\n");
    assert!(e.starts_with("balls[0]"), "{e}");
    assert!(e.contains("unknown key `radiu`"), "{e}");
    let e = error("dim = 2\ngravity = [0.0, -9.81]\n");
    assert!(e.contains("unknown key `gravity`"), "{e}");
    let e = error("dim = 2\n[world.border]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\nperiodc = true\n");
    assert!(e.starts_with("world.border"), "{e}");
}

#[test]
fn missing_required_keys_are_named() {
    let e = error("dim = 2\n[[balls]]\npos = [0.0, 0.0]\nmass = 1.0\n");
    assert!(
        e.starts_with("balls[0]") && e.contains("missing key `radius`"),
        "{e}"
    );
    let e = error("name = \"no dim\"\n");
    assert!(e.contains("missing key `dim`"), "{e}");
}

#[test]
fn bad_values_name_the_field_and_say_what_is_wrong() {
    let ball = |extra: &str| {
        format!("dim = 2\n[[balls]]\npos = [0.0, 0.0]\nradius = 0.1\nmass = 1.0\n{extra}")
    };
    let cases = [
        ("dim = 4\n".to_owned(), "dim: must be 2 or 3, got 4"),
        ("dim = 2\n[[balls]]\npos = [0.0, 0.0]\nradius = -0.1\nmass = 1.0\n".to_owned(), "balls[0].radius: must be > 0, got -0.1"),
        ("dim = 2\n[[balls]]\npos = [0.0, 0.0]\nradius = 0.1\nmass = 0.0\n".to_owned(), "balls[0].mass: must be > 0, got 0"),
        (ball("restitution = 1.5\n"), "balls[0].restitution: must be in [0, 1], got 1.5"),
        (ball("vel = [nan, 0.0]\n"), "balls[0].vel[0]: must be finite, got NaN"),
        (ball("vel = [1.0, 0.0, 0.0]\n"), "balls[0].vel: must have exactly 2 components (dim = 2), got 3"),
        ("dim = 2\n[world]\ngravity = [0.0, -inf]\n".to_owned(), "world.gravity[1]: must be finite, got -inf"),
        ("dim = 2\n[world]\nfriction = -1\n".to_owned(), "world.friction: must be >= 0, got -1"),
        ("dim = 2\n[world.border]\nmin = [0.0, 0.0]\nmax = [1.0, 0.0]\n".to_owned(), "world.border.min[1]"),
        ("dim = 2\n[[boxes]]\ncenter = [0.0, 0.0]\nhalf_extents = [1.0, -1.0]\n".to_owned(), "boxes[0].half_extents[1]: must be >= 0"),
        ("dim = 2\n[[boxes]]\ncenter = [0.0, 0.0]\nhalf_extents = [1.0, 1.0]\naxis_angle = [0.0, 0.0, 1.0]\n".to_owned(), "boxes[0].axis_angle: is for dim = 3"),
        ("dim = 3\n[[boxes]]\ncenter = [0.0, 0.0, 0.0]\nhalf_extents = [1.0, 1.0, 1.0]\nangle = 0.3\n".to_owned(), "boxes[0].angle: is for dim = 2"),
        ("dim = 2\n[world]\ninelastic = \"glue\"\n".to_owned(), "world.inelastic"),
    ];
    for (text, expected) in cases {
        let e = error(&text);
        assert!(
            e.starts_with(expected),
            "for\n{text}\nexpected `{expected}...`, got `{e}`"
        );
    }
}

#[test]
fn balls_must_start_inside_a_reflecting_border_but_may_touch_it() {
    let scene = |x: f64| {
        format!(
            "dim = 2\n[world.border]\nmin = [-1.0, -1.0]\nmax = [1.0, 1.0]\n[[balls]]\npos = [{x}, 0.0]\nradius = 0.25\nmass = 1.0\n"
        )
    };
    assert!(
        parse_scene(&scene(0.75)).is_ok(),
        "touching the wall is allowed"
    );
    let e = error(&scene(0.8));
    assert!(
        e.starts_with("balls[0].pos: the ball must start inside the border"),
        "{e}"
    );
}

#[test]
fn invalid_toml_reports_the_line() {
    let e = error("dim = 2\n[[balls]\n");
    assert!(e.contains("line 2"), "{e}");
}

#[test]
fn overlapping_balls_are_refused_touching_ones_are_not() {
    let two = |x: f64| {
        format!(
            "dim = 2\n[[balls]]\npos = [0.0, 0.0]\nradius = 0.5\nmass = 1\n[[balls]]\npos = [{x}, 0.0]\nradius = 0.5\nmass = 1\n"
        )
    };
    assert!(parse_scene(&two(1.0)).is_ok(), "touching is allowed");
    assert!(
        parse_scene(&two(1.0 - 5e-10)).is_ok(),
        "overlap within 1e-9 is allowed"
    );
    let e = error(&two(0.9));
    assert!(
        e.starts_with("balls[1].pos: overlaps balls[0] by 1.000e-1 m"),
        "{e}"
    );
}

#[test]
fn overlaps_count_across_a_periodic_boundary() {
    let text = "dim = 2\n[world.border]\nmin = [0.0, 0.0]\nmax = [10.0, 10.0]\nperiodic = true\n\
                [[balls]]\npos = [0.2, 5.0]\nradius = 0.5\nmass = 1\n[[balls]]\npos = [9.7, 5.0]\nradius = 0.5\nmass = 1\n";
    let e = error(text);
    assert!(e.starts_with("balls[1].pos: overlaps balls[0]"), "{e}");
}

#[test]
fn a_ball_inside_a_box_is_refused() {
    let text = "dim = 3\n[[boxes]]\ncenter = [0.0, 0.0, 0.0]\nhalf_extents = [1.0, 1.0, 0.1]\naxis_angle = [0.0, 0.3, 0.0]\n\
                [[balls]]\npos = [0.0, 0.0, 0.2]\nradius = 0.2\nmass = 1\n";
    let e = error(text);
    assert!(e.starts_with("balls[0].pos: overlaps boxes[0]"), "{e}");
    let resting = "dim = 2\n[[boxes]]\ncenter = [0.0, -0.5]\nhalf_extents = [1.0, 0.5]\n[[balls]]\npos = [0.3, 0.2]\nradius = 0.2\nmass = 1\n";
    assert!(
        parse_scene(resting).is_ok(),
        "a ball resting on a box touches it"
    );
}

#[test]
fn a_large_gas_is_validated_quickly_and_accepted() {
    use carom_sim::scenes::gas::{GasParams, gas};
    let scene = gas::<3>(&GasParams {
        n: 50_000,
        fraction: 0.45,
        periodic: true,
        ..GasParams::default()
    })
    .unwrap();
    scene.validate().unwrap();
}

/// Two balls of radius 0.016 and 0.020 m in a 3.7 m box whose centre is `(c, c)`.
fn small_balls_at(c: f64) -> String {
    format!(
        "
dim = 2
[world]
gravity = [8.16, 2.69]
[world.border]
min = [{}, {}]
max = [{}, {}]
[[balls]]
pos = [{}, {}]
vel = [1.99, 0.029]
radius = 0.015625
mass = 77.2
[[balls]]
pos = [{}, {}]
radius = 0.01953125
mass = 3.87
",
        c - 1.84375,
        c - 1.08984375,
        c + 1.84375,
        c + 1.08984375,
        c - 0.3359375,
        c - 0.8515625,
        c - 1.390625,
        c - 0.80859375
    )
}

#[test]
fn a_ball_smaller_than_the_precision_resolves_where_it_is_is_refused_naming_its_radius() {
    // At 5e4 m f32 resolves 8 ε x = 0.048 m, f64 8.9e-11 m: these balls passed through
    // each other in f32 there (a fuzzed scene).
    let LoadedScene::D2(s) = parse_scene(&small_balls_at(-5e4)).expect("valid in f64") else {
        panic!("a 2D scene")
    };
    let e = s.cast::<f32>().expect_err("too small for f32 there");
    assert_eq!(e.field, "balls[0].radius", "{e}");
    assert!(e.message.contains("--precision f64"), "{e}");
    // Near the origin f32 resolves them too.
    let LoadedScene::D2(s) = parse_scene(&small_balls_at(0.0)).expect("valid") else {
        panic!("a 2D scene")
    };
    s.cast::<f32>().expect("resolved near the origin");
    // In f64 the same balls at 1e14 m are beyond f64's resolution too (0.18 m there):
    // the message does not send the user to the precision already in use.
    let e = parse_scene(&small_balls_at(-1e14)).expect_err("too small for f64 there");
    assert_eq!(e.field, "balls[0].radius", "{e}");
    assert!(e.message.contains("coordinates nearer the origin"), "{e}");
    assert!(!e.message.contains("--precision"), "{e}");
}
