//! Ground truth: an orthographic ray caster over the explicit micro-geometry ([`crate::geometry`]).
//! (Being written: see the module plan in ARCHITECTURE.md.)
