//! parry 0.31's BVH as the peer of carom's broad phases (2D and 3D, `f32`).
//!
//! One frame fills the leaves with the balls' bounding boxes; one-shot frames build the
//! tree anew (`Bvh::from_leaves`, binned), coherent frames update the leaves in place and
//! refit; then the tree is traversed against itself. parry reports the pairs of
//! overlapping *boxes*, unsorted: less work than carom's broad phases, whose pairs pass
//! the exact ball test and come sorted. The pair count is returned so a caller can check
//! both found the same neighbourhoods.

use carom_broad::scenes::Scene;

use crate::broad::Peer;

macro_rules! parry_bvh {
    ($name:ident, $parry:ident, $d:literal) => {
        #[doc = concat!("parry's BVH in ", stringify!($d), "D.")]
        #[derive(Default)]
        pub struct $name {
            bvh: Option<$parry::partitioning::Bvh>,
            workspace: $parry::partitioning::BvhWorkspace,
            leaves: Vec<$parry::bounding_volume::Aabb>,
            pairs: Vec<(u32, u32)>,
        }

        impl Peer<$d> for $name {
            fn frame(&mut self, scene: &Scene<f64, $d>, coherent: bool) -> usize {
                use $parry::bounding_volume::Aabb;
                use $parry::math::Vector;
                use $parry::partitioning::{Bvh, BvhBuildStrategy};
                self.leaves.clear();
                for (c, &r) in scene.centers.iter().zip(&scene.radii) {
                    let lo: [f32; $d] = core::array::from_fn(|k| (c[k] - r) as f32);
                    let hi: [f32; $d] = core::array::from_fn(|k| (c[k] + r) as f32);
                    self.leaves
                        .push(Aabb::new(Vector::from_array(lo), Vector::from_array(hi)));
                }
                match (&mut self.bvh, coherent) {
                    (Some(bvh), true) => {
                        for (i, aabb) in self.leaves.iter().enumerate() {
                            bvh.insert_or_update_partially(*aabb, i as u32, 0.0);
                        }
                        bvh.refit(&mut self.workspace);
                    }
                    _ => {
                        self.bvh = Some(Bvh::from_leaves(BvhBuildStrategy::Binned, &self.leaves));
                    }
                }
                self.pairs.clear();
                let pairs = &mut self.pairs;
                if let Some(bvh) = &self.bvh {
                    bvh.traverse_bvtt_single_tree::<false>(&mut self.workspace, &mut |a, b| {
                        pairs.push((a, b));
                    });
                }
                self.pairs.len()
            }
        }
    };
}

parry_bvh!(ParryBvh2, parry2d, 2);
parry_bvh!(ParryBvh3, parry3d, 3);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bvh_finds_every_ball_pair_among_its_box_pairs() {
        // Box pairs are a superset of ball pairs (a ball's box holds the ball).
        let s = Scene::<f64, 3>::uniform(500, 0.5, 0.3, 0.0, 3);
        let mut ball_pairs = 0;
        for i in 0..s.len() {
            for j in i + 1..s.len() {
                if (s.centers[i] - s.centers[j]).norm() <= s.radii[i] + s.radii[j] {
                    ball_pairs += 1;
                }
            }
        }
        let mut peer = ParryBvh3::default();
        let boxes = peer.frame(&s, false);
        assert!(
            boxes >= ball_pairs && ball_pairs > 0,
            "{boxes} {ball_pairs}"
        );
        assert_eq!(peer.frame(&s, true), boxes, "a refit of the same scene");
        let s2 = Scene::<f64, 2>::uniform(300, 0.5, 0.3, 0.0, 3);
        assert!(ParryBvh2::default().frame(&s2, false) > 0);
    }
}
