//! The stepped engine's elastic gas against rapier2d's on the same scene (moved here from
//! carom-sim's tests with the rapier2d peer): carom keeps the energy to rounding, rapier2d
//! loses a visible fraction of it. The figures are the report's own (section 3's rows).
#![cfg(feature = "rapier")]

use carom_report::peer::rapier::RapierScene;
use carom_report::throughput::{GAS_DT, engine, stepped, stepped_gas};

#[test]
fn the_gas_drifts_far_less_than_rapier2d_on_the_same_scene() {
    // 1,000 balls for 300 steps of 1/60 s: 5 s of simulated time.
    let rows = stepped(1000, 1, 300).unwrap();
    let drift = |e: &str| {
        rows.iter()
            .find(|r| r.engine == e)
            .and_then(|r| r.energy_drift)
            .unwrap()
    };
    let (carom, rapier) = (drift(engine::STEPPED), drift(engine::RAPIER));
    let settings = RapierScene::new(&stepped_gas(10).unwrap(), GAS_DT)
        .unwrap()
        .settings();
    println!("energy drift over 5 s: carom {carom:e}, {settings} {rapier:e}");
    assert!(carom.abs() < 1e-12, "carom {carom:e}");
    assert!(
        rapier.abs() > 1e3 * carom.abs().max(1e-16),
        "rapier {rapier:e}"
    );
}
