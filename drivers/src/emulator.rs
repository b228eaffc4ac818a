//! A Pioneer controller in software that speaks P2OS (built by the P2OS issue).
