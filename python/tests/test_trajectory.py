"""Joint trajectories through the Python client (issue 28) against `limber simarm`: one
followed to its goal within the tolerance (``wait_done``), paused by a scaling of 0 and
resumed by 1, an invalid one raising ``ValueError`` before anything is sent, one naming a
joint the arm lacks refused by the driver with the cause. Every wait has a timeout;
nothing asserts speed."""

import pytest

from limber import ActArrayClient, MotionResult, Status
from test_client import T, unique_domain
from test_paper_rows import SimArm


@pytest.fixture
def arm():
    domain = unique_domain()
    s = SimArm(domain)
    try:
        with ActArrayClient.connect("simarm/actarray/0", domain, timeout=T) as a:
            yield a
    finally:
        s.stop()


def test_a_trajectory_is_followed_to_its_goal(arm: ActArrayClient) -> None:
    q0 = arm.wait_state(T).actuators[0].position
    ticket = arm.follow_trajectory(
        joints=[0, 5],
        times=[0.5, 1.0],
        positions=[[q0 + 0.1, 0.05], [q0 + 0.2, 0.1]],
        velocities=[[0.3, 0.15], [0.0, 0.0]],
        goal_tolerance=[0.001, 0.001],
        path_tolerance=[0.05, 0.05],
    )
    assert arm.wait_outcome(ticket, T) is Status.OK
    done = arm.wait_done(ticket, T)
    assert done.result is MotionResult.REACHED, done.sentence
    assert done.max_error <= 0.001
    assert abs(done.positions[0] - (q0 + 0.2)) <= 0.001


def test_scaling_pauses_and_resumes(arm: ActArrayClient) -> None:
    q0 = arm.wait_state(T).actuators[0].position
    ticket = arm.follow_trajectory(joints=[0], times=[20.0], positions=[[q0 + 1.0]])
    assert arm.wait_outcome(ticket, T) is Status.OK
    assert arm.wait_outcome(arm.set_trajectory_scale(0.0), T) is Status.OK
    arm.wait_state(T)
    held = arm.wait_state(T).actuators[0].position
    for _ in range(10):
        assert arm.wait_state(T).actuators[0].position == held
    assert arm.wait_outcome(arm.set_trajectory_scale(2.0), T) is Status.CLAMPED
    # A newer trajectory takes over: the first ends preempted.
    back = arm.follow_trajectory(joints=[0], times=[0.5], positions=[[q0]])
    assert arm.wait_done(ticket, T).result is MotionResult.PREEMPTED
    assert arm.wait_done(back, T).result is MotionResult.REACHED


def test_invalid_trajectories_are_refused_with_the_reason(arm: ActArrayClient) -> None:
    with pytest.raises(ValueError, match="not after the previous point"):
        arm.follow_trajectory(joints=[0], times=[1.0, 0.5], positions=[[0.0], [0.1]])
    with pytest.raises(ValueError, match="not finite"):
        arm.follow_trajectory(joints=[0], times=[1.0], positions=[[float("nan")]])
    ticket = arm.follow_trajectory(joints=[0, 20], times=[1.0], positions=[[0.0, 0.0]])
    assert arm.wait_outcome(ticket, T) is Status.UNKNOWN_JOINT
