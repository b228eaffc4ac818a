//! Kinematics: the Pioneer arm in closed form and generic chains (built by the kinematics issue).
