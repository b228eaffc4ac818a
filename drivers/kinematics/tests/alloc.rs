//! The solvers do not allocate: a counting global allocator sees no allocation during
//! Pioneer FK/IK/SETPOSITION/VECMOVE and chain FK/IK (success and failure), counted on
//! the thread that solves.

use limber_counting_alloc::{Counting, allocations_in};
use limber_kinematics::chain::{Chain, IkTarget, NumericIkOptions};
use limber_kinematics::pioneer::{
    ApproachPreference, PioneerGeometry, PioneerIkOptions, VecMoveOptions,
};
use nalgebra::Vector3;

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn solvers_do_not_allocate() {
    let g = PioneerGeometry::default();
    let o = PioneerIkOptions::default();
    let theta = [0.2, 0.3, 0.4, -0.1, 0.5];
    let c6 = Chain::default_6dof();
    let c7 = Chain::default_7dof();
    let no = NumericIkOptions::default();
    let h6 = c6.home();
    let h7 = c7.home();
    let t6 = c6.fk(&[0.3, -1.2, 1.1, -0.5, 0.7, 0.2]).unwrap();
    let t7 = c7.fk(&[0.3, 0.2, -0.4, -1.5, 0.2, 1.9, 0.4]).unwrap();
    let n = allocations_in(|| {
        let pose = g.fk(&theta).unwrap();
        assert!(g.solve_pose(&pose, &[0.0; 5], &o).is_ok());
        assert!(g.pose_candidates(&pose, &[0.0; 5], &o).is_ok());
        assert!(
            g.solve_position(&pose.position, ApproachPreference::Down, &[0.0; 5], &o)
                .is_ok()
        );
        let far = Vector3::new(2.0, 0.0, 0.0);
        assert!(
            g.solve_position(&far, ApproachPreference::Current, &[0.0; 5], &o)
                .is_err()
        );
        let mut plan = g
            .vecmove(
                &theta,
                &Vector3::new(0.0, -1.0, 0.0),
                0.03,
                &VecMoveOptions::default(),
            )
            .unwrap();
        assert!(plan.all(|w| w.is_ok()));
        assert!(c6.ik(&IkTarget::Pose(t6), &h6, &no).is_ok());
        assert!(c6.ik(&IkTarget::Position(t6.position), &h6, &no).is_ok());
        assert!(c7.ik(&IkTarget::Pose(t7), &h7, &no).is_ok());
        let unreachable = IkTarget::Position(Vector3::new(0.0, 0.0, 1.05));
        assert!(c6.ik(&unreachable, &h6, &no).is_err());
    });
    assert_eq!(n, 0, "allocations during solves");
}
