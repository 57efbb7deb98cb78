//! Stage — tooth bending (MODEL §5.5): finite-element model of worm and wheel, expanded on a
//! function basis for the LTCA. This module holds the linear-elasticity finite elements; the
//! gear models and the function basis build on them.

pub mod basis;
pub mod fe;
pub mod wheel_mesh;
pub mod wheel_model;
