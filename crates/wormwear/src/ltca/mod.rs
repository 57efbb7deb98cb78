//! Stage 3 — loaded tooth contact analysis (MODEL §5).

pub mod solver;
