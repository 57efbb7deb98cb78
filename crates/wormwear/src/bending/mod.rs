//! Stage — tooth bending (MODEL §5.5): finite-element model of worm and wheel, expanded on a
//! function basis for the LTCA. This module holds the linear-elasticity finite elements; the
//! gear models and the function basis build on them.

pub mod basis;
pub mod fe;
pub mod model;
pub(crate) mod relation;
pub mod root_mesh;
pub mod wheel_mesh;
pub mod wheel_model;
pub mod wheel_root;
pub mod wheel_shaft;
pub mod worm_deflection;
pub mod worm_mesh;
pub mod worm_model;

/// Serde of a dense matrix as (rows, cols, row-major values), for the coefficient cache.
pub(crate) mod mat_serde {
    use faer::Mat;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    struct Dense {
        rows: usize,
        cols: usize,
        values: Vec<f64>,
    }

    pub fn serialize<S: Serializer>(m: &Mat<f64>, s: S) -> Result<S::Ok, S::Error> {
        let values = (0..m.nrows())
            .flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)]))
            .collect();
        Dense {
            rows: m.nrows(),
            cols: m.ncols(),
            values,
        }
        .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Mat<f64>, D::Error> {
        let dense = Dense::deserialize(d)?;
        if dense.values.len() != dense.rows * dense.cols {
            return Err(serde::de::Error::custom(
                "matrix size does not match its values",
            ));
        }
        Ok(Mat::from_fn(dense.rows, dense.cols, |i, j| {
            dense.values[i * dense.cols + j]
        }))
    }
}
