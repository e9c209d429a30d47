//! Scenes defined once and shared by tests, benches, examples and the report.
//!
//! * [`collision_lab`]: the four screens of PhET's Collision Lab with their default
//!   initial states and options.
//! * [`gas`]: many balls in a box (reflecting or periodic) at a given area or volume
//!   fraction, with random velocities and zero total momentum — the throughput scenes.
//! * [`classic`]: small textbook set-ups with closed-form answers (head-on and oblique
//!   collisions, Newton's cradle, a dropped ball).
//! * [`fuzz`]: random scenes of every kind the scene format allows, drawn from a seed,
//!   and the invariants a run of one must keep (robustness campaigns).
//! * [`pile`]: rows of balls dropped into a narrow box under gravity with friction, where
//!   they form a pile (the stepped engine's pile test and its draws over seeds).

pub mod classic;
pub mod collision_lab;
pub mod fuzz;
pub mod gas;
pub mod pile;

/// The deterministic random generator of every shared scene: carom-broad's SplitMix64,
/// so scenes built from a seed are identical on every machine and in every version,
/// which a dependency's generator does not promise.
pub use carom_broad::scenes::SplitMix64;

#[cfg(test)]
mod tests {
    use super::SplitMix64;

    #[test]
    fn splitmix_matches_the_reference_sequence() {
        // First outputs for seed 1234567, computed by an independent (Python) implementation
        // of the published algorithm.
        let mut g = SplitMix64::new(1_234_567);
        assert_eq!(g.next_u64(), 6_457_827_717_110_365_317);
        assert_eq!(g.next_u64(), 3_203_168_211_198_807_973);
    }

    #[test]
    fn uniform_and_normal_have_the_right_moments() {
        let mut g = SplitMix64::new(7);
        let n = 200_000;
        let (mut s, mut s2, mut z2) = (0.0, 0.0, 0.0);
        for _ in 0..n {
            let u = g.next_f64();
            assert!((0.0..1.0).contains(&u));
            s += u;
            s2 += u * u;
            let z = g.normal();
            z2 += z * z;
        }
        let nf = f64::from(n);
        assert!((s / nf - 0.5).abs() < 5e-3);
        assert!((s2 / nf - 1.0 / 3.0).abs() < 5e-3);
        assert!((z2 / nf - 1.0).abs() < 1e-2);
    }
}
