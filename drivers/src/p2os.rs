//! The P2OS/ARCOS protocol of the Pioneer controller (built by the P2OS issue).
