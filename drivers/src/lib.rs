//! limber-drivers: P2OS, emulator, kinematics, the Pioneer driver and simarm.
