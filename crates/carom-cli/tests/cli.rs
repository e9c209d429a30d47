//! `carom run` against its contract (docs/scene-format.md): output lines, exit statuses,
//! one-line errors naming the file and the field.

use std::ops::Deref;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

fn carom(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_carom"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// A scene file in a directory of its own, removed when the value is dropped.
struct SceneFile {
    path: PathBuf,
    _dir: tempfile::TempDir,
}

impl Deref for SceneFile {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

/// Writes `text` to a fresh scene file.
fn scene_file(name: &str, text: &str) -> SceneFile {
    let dir = tempfile::Builder::new()
        .prefix("carom-cli-test-")
        .tempdir()
        .unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    SceneFile { path, _dir: dir }
}

const INTRO: &str = r#"
dim = 2
name = "intro"
[world.border]
min = [-2.0, -0.55]
max = [2.0, 0.55]
[[balls]]
pos = [-1.0, 0.0]
vel = [1.0, 0.0]
radius = 0.15
mass = 0.5
[[balls]]
pos = [1.0, 0.0]
vel = [-0.5, 0.0]
radius = 0.15
mass = 1.5
"#;

fn lines(out: &Output) -> Vec<Value> {
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone())
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("not JSON: {l}: {e}")))
        .collect()
}

#[test]
fn a_run_prints_samples_events_and_one_summary_in_time_order() {
    let path = scene_file("intro.toml", INTRO);
    let out = lines(&carom(&[
        "run",
        path.to_str().unwrap(),
        "--until",
        "3",
        "--every",
        "1",
        "--events",
    ]));
    let summary = out.last().unwrap();
    assert_eq!(summary["summary"]["engine"], "event");
    assert_eq!(summary["summary"]["ball_ball"], 1);
    assert_eq!(summary["summary"]["ball_border"], 1);
    let pipeline: Vec<&str> = summary["summary"]["pipeline"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap())
        .collect();
    assert!(
        pipeline.contains(&"toi:ball-border") && !pipeline.contains(&"toi:ball-box"),
        "{pipeline:?}"
    );
    let (e0, e1) = (
        summary["summary"]["energy_initial"].as_f64().unwrap(),
        summary["summary"]["energy_final"].as_f64().unwrap(),
    );
    assert!((e0 - e1).abs() < 1e-12 && (e0 - 0.4375).abs() < 1e-15);
    let times: Vec<f64> = out[..out.len() - 1]
        .iter()
        .map(|l| l["t"].as_f64().unwrap())
        .collect();
    assert!(
        times.windows(2).all(|w| w[0] <= w[1]),
        "time order: {times:?}"
    );
    let samples: Vec<&Value> = out.iter().filter(|l| l.get("pos").is_some()).collect();
    assert_eq!(samples.len(), 4, "t = 0, 1, 2, 3");
    let event = out.iter().find(|l| l["event"] == "ball-ball").unwrap();
    assert!((event["t"].as_f64().unwrap() - 1.7 / 1.5).abs() < 1e-14);
    assert_eq!(
        (event["i"].as_u64(), event["j"].as_u64()),
        (Some(0), Some(1))
    );
    // After the collision: Collision Lab's −1.25 and 0.25 m/s.
    assert_eq!(samples[2]["vel"][0][0].as_f64(), Some(-1.25));
    assert_eq!(samples[2]["vel"][1][0].as_f64(), Some(0.25));
}

#[test]
fn a_backward_run_then_forward_returns_to_the_start() {
    let path = scene_file("intro-back.toml", INTRO);
    let out = lines(&carom(&[
        "run",
        path.to_str().unwrap(),
        "--until",
        "-4",
        "--events",
    ]));
    let end = &out[out.len() - 2];
    assert_eq!(end["t"].as_f64(), Some(-4.0));
    let summary = &out[out.len() - 1]["summary"];
    assert!(summary["ball_ball"].as_u64().unwrap() >= 1);
    // Run forward from the state at −4 for 4 s: back to the initial state.
    let back = format!(
        "dim = 2\n[world.border]\nmin = [-2.0, -0.55]\nmax = [2.0, 0.55]\n[[balls]]\npos = {}\nvel = {}\nradius = 0.15\nmass = 0.5\n[[balls]]\npos = {}\nvel = {}\nradius = 0.15\nmass = 1.5\n",
        end["pos"][0], end["vel"][0], end["pos"][1], end["vel"][1]
    );
    let path = scene_file("intro-forward.toml", &back);
    let out = lines(&carom(&["run", path.to_str().unwrap(), "--until", "4"]));
    let last = &out[out.len() - 2];
    for (k, x) in [(0, -1.0), (1, 1.0)] {
        assert!(
            (last["pos"][k][0].as_f64().unwrap() - x).abs() < 1e-12,
            "{last}"
        );
    }
}

/// A backward run's sample times are negative, and a list of them is read as one value
/// (clap once took `-0.25,-0.5` for a flag), in the run's order: the ball at 1 m/s is
/// where `v t` puts it at each.
#[test]
fn a_backward_run_takes_a_list_of_negative_sample_times() {
    let path = scene_file("intro-back-at.toml", INTRO);
    let out = lines(&carom(&[
        "run",
        path.to_str().unwrap(),
        "--until",
        "-0.5",
        "--at",
        "-0.25,-0.125",
    ]));
    let samples = &out[..out.len() - 1];
    let times: Vec<f64> = samples.iter().map(|l| l["t"].as_f64().unwrap()).collect();
    assert_eq!(times, vec![-0.125, -0.25, -0.5]);
    for l in samples {
        let t = l["t"].as_f64().unwrap();
        // Ball 0 starts at -1 m moving at 1 m/s and meets nothing within 0.5 s back.
        let x = l["pos"][0][0].as_f64().unwrap();
        assert!((x - (-1.0 + t)).abs() < 1e-12, "{l}");
    }
}

#[test]
fn f32_precision_prints_single_precision_numbers() {
    let path = scene_file("intro-f32.toml", INTRO);
    let out = lines(&carom(&[
        "run",
        path.to_str().unwrap(),
        "--until",
        "2",
        "--precision",
        "f32",
    ]));
    assert_eq!(out[0]["vel"][0][0].as_f64(), Some(-1.25));
}

fn failure(args: &[&str]) -> String {
    let out = carom(args);
    assert_eq!(
        out.status.code(),
        Some(2),
        "stdout: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(out.stdout.is_empty(), "nothing is simulated");
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    err
}

#[test]
fn bad_scenes_exit_2_with_one_line_naming_the_file_and_the_field() {
    let path = scene_file(
        "bad.toml",
        &INTRO.replace("radius = 0.15\nmass = 1.5", "radius = -0.15\nmass = 1.5"),
    );
    let err = failure(&["run", path.to_str().unwrap(), "--until", "1"]);
    assert!(
        err.contains("bad.toml: balls[1].radius: must be > 0, got -0.15"),
        "{err}"
    );
    let path = scene_file("typo.toml", &INTRO.replace("mass = 0.5", "mas = 0.5"));
    let err = failure(&["run", path.to_str().unwrap(), "--until", "1"]);
    assert!(
        err.contains("typo.toml: balls[0].mas: unknown key `mas`"),
        "{err}"
    );
    let path = scene_file(
        "outside.toml",
        &INTRO.replace("pos = [1.0, 0.0]", "pos = [1.9, 0.0]"),
    );
    let err = failure(&["run", path.to_str().unwrap(), "--until", "1"]);
    assert!(
        err.contains("balls[1].pos: the ball must start inside the border"),
        "{err}"
    );
    let err = failure(&["run", "/nonexistent/scene.toml", "--until", "1"]);
    assert!(
        err.contains("/nonexistent/scene.toml: cannot read the scene file"),
        "{err}"
    );
}

#[test]
fn bad_flags_exit_2() {
    let path = scene_file("flags.toml", INTRO);
    let p = path.to_str().unwrap();
    assert!(
        failure(&[
            "run", p, "--until", "1", "--engine", "event", "--dt", "0.01"
        ])
        .contains("--integrator and --dt")
    );
    assert!(failure(&["run", p, "--until", "1", "--at", "2"]).contains("--at"));
    assert!(failure(&["run", p, "--until", "1", "--engine", "fast"]).contains("fast"));
    assert!(failure(&["run", p, "--until", "nan"]).contains("--until"));
    assert!(failure(&["run", p]).contains("--until"));
    assert!(failure(&["run", p, "--until", "1", "--threads", "0"]).contains("--threads"));
    assert!(failure(&["run", p, "--until", "1", "--threads", "100000"]).contains("--threads"));
}

#[test]
fn the_output_file_receives_the_lines() {
    let path = scene_file("out.toml", INTRO);
    let out_path = path.with_file_name("out.jsonl");
    let out = carom(&[
        "run",
        path.to_str().unwrap(),
        "--until",
        "1",
        "--out",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success() && out.stdout.is_empty());
    let text = std::fs::read_to_string(out_path).unwrap();
    assert_eq!(text.lines().count(), 2, "one sample and the summary");
}

#[test]
fn a_3d_stick_scene_runs_on_the_stepped_engine_forced_or_chosen() {
    // Two balls meet off-centre and stick into a tumbling pair, which bounces off the
    // walls of a box.
    let path = scene_file(
        "stick3d.toml",
        r#"dim = 3
[world]
restitution = 0.0
inelastic = "stick"
[world.border]
min = [-1.0, -1.0, -1.0]
max = [1.0, 1.0, 1.0]
[[balls]]
pos = [-0.5, 0.0, 0.0]
vel = [1.0, 0.0, 0.1]
radius = 0.1
mass = 1.0
[[balls]]
pos = [0.5, 0.1, 0.0]
vel = [-1.0, 0.0, 0.0]
radius = 0.15
mass = 2.0
"#,
    );
    let file = path.to_str().unwrap();
    for engine in ["stepped", "auto"] {
        let out = carom(&[
            "run", file, "--engine", engine, "--until", "2", "--every", "1", "--events",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let lines = lines(&out);
        let summary = &lines.last().unwrap()["summary"];
        assert_eq!(summary["engine"], "stepped", "{summary}");
        let pipeline = summary["pipeline"].as_array().unwrap();
        assert!(pipeline.iter().any(|p| p == "response:stick"), "{summary}");
        assert_eq!(summary["ball_ball"], 1, "{summary}");
        // Momentum is kept through the stick; the walls then change it.
        let stuck = lines.iter().find(|l| l["t"] == 1.0).unwrap();
        let p: Vec<f64> = (0..3)
            .map(|k| {
                stuck["vel"][0][k].as_f64().unwrap() + 2.0 * stuck["vel"][1][k].as_f64().unwrap()
            })
            .collect();
        let p0 = [1.0 - 2.0, 0.0, 0.1];
        for k in 0..3 {
            assert!((p[k] - p0[k]).abs() < 1e-12, "{p:?}");
        }
        // The members keep their distance.
        let pos = |l: &serde_json::Value, i: usize| -> Vec<f64> {
            (0..3).map(|k| l["pos"][i][k].as_f64().unwrap()).collect()
        };
        let (a, b) = (pos(stuck, 0), pos(stuck, 1));
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        assert!((d - 0.25).abs() < 1e-9, "{d}");
    }
}

/// Two balls dropped one above the other settle into a pile: sustained contact, which
/// the event engine cannot resolve. `auto` hands the run over to the stepped engine and
/// says so (summary and stderr); `--engine event` stops with status 1 and the reason.
#[test]
fn auto_hands_a_pile_over_to_the_stepped_engine_and_says_so() {
    let path = scene_file(
        "pile.toml",
        "dim = 2
[world]
gravity = [0.0, -9.81]
restitution = 0.5
[world.border]
min = [-1.0, 0.0]
max = [1.0, 3.0]
restitution = 0.5
[[balls]]
pos = [0.0, 0.5]
radius = 0.1
mass = 1.0
[[balls]]
pos = [0.0, 1.2]
radius = 0.1
mass = 1.0
",
    );
    let file = path.to_str().unwrap();
    let out = carom(&["run", file, "--until", "3", "--events"]);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let lines = lines(&out);
    let summary = &lines.last().unwrap()["summary"];
    assert_eq!(summary["engine"], "event+stepped", "{summary}");
    let t = summary["hand_over"]["t"].as_f64().unwrap();
    assert!(t > 0.5 && t < 1.5, "{summary}");
    let reason = summary["hand_over"]["reason"].as_str().unwrap();
    assert!(reason.contains("sustained contact"), "{reason}");
    assert!(
        stderr.contains("went over from the event engine to the stepped engine"),
        "{stderr}"
    );
    // The pile stands at heights 0.1 and 0.3.
    let end = &lines[lines.len() - 2];
    assert_eq!(end["t"], 3.0);
    for (i, height) in [0.1, 0.3].into_iter().enumerate() {
        let y = end["pos"][i][1].as_f64().unwrap();
        assert!((y - height).abs() < 1e-8, "ball {i} at {y}");
    }
    // Event lines keep one clock across the hand-over.
    let times: Vec<f64> = lines
        .iter()
        .filter_map(|l| l["event"].as_str().and(l["t"].as_f64()))
        .collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "{times:?}");

    let forced = carom(&["run", file, "--until", "3", "--engine", "event"]);
    assert_eq!(forced.status.code(), Some(1));
    let err = String::from_utf8_lossy(&forced.stderr);
    assert!(
        err.contains("sustained contact") && err.contains("--engine auto"),
        "{err}"
    );
}

/// The stderr of a run that must fail with status 2 (bad flags).
fn rejected(args: &[&str]) -> String {
    let out = carom(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    assert!(out.stdout.is_empty(), "{args:?}");
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    err
}

#[test]
fn report_options_are_checked_before_anything_runs() {
    assert!(rejected(&["report", "--fast"]).contains("--fast"));
    let both = rejected(&["report", "--quick", "--full"]);
    assert!(
        both.contains("--quick") && both.contains("--full"),
        "{both}"
    );
    assert!(rejected(&["report", "--out"]).contains("--out"));
    assert!(rejected(&["report", "extra"]).contains("extra"));
    // --help lists the options and runs nothing.
    let help = carom(&["report", "--help"]);
    assert!(help.status.success());
    let text = String::from_utf8(help.stdout).unwrap();
    for flag in ["--quick", "--full", "--out"] {
        assert!(text.contains(flag), "{flag}: {text}");
    }
    assert!(text.contains("carom-report"), "the default folder: {text}");
}
