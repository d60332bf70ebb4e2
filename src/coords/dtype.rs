//! How weights are stored: float32, what every front end and GPU kernel gives by
//! default, or float64, where a study checks rows to more digits than float32
//! holds (its rounding is 6e-8 of a weight: a row sum of a point 1e9 cage
//! diagonals away is off by far more once its weights are rounded). Rows are
//! computed in float64 either way; float64 keeps them as computed.

use super::Method;
use glam::DVec3;
use rayon::prelude::*;

/// The element type of a weights matrix.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Dtype {
    #[default]
    Float32,
    Float64,
}

/// A dtype that cannot be used: an unknown name, or one a family cannot fill.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DtypeError {
    #[error("dtype {0:?} is not float32 or float64 (f32, f64)")]
    Unknown(String),
    #[error(
        "dtype float64: harmonic coordinates are solved in float32 on their grid, whose \
         error (about 1e-3 at grid 64) is far above float32's rounding; bind them as float32"
    )]
    Harmonic,
    #[error(
        "dtype float64: {family} weights are sampled in float32 from their grid, whose \
         error is far above float32's rounding; bind them as float32"
    )]
    SampledFromGrid { family: &'static str },
    #[error("dtype float64: weights are computed on the CPU (GPU kernels compute in float32)")]
    NotOnGpu,
}

impl Dtype {
    /// The name metadata and NumPy give it.
    pub fn id(self) -> &'static str {
        match self {
            Dtype::Float32 => "float32",
            Dtype::Float64 => "float64",
        }
    }

    /// The one parser of a dtype, wherever it comes from (`--dtype`, Python's
    /// `dtype=`, a `W.json`): "float32" or "f32", "float64" or "f64".
    pub fn parse(text: &str) -> Result<Dtype, DtypeError> {
        match text {
            "float32" | "f32" => Ok(Dtype::Float32),
            "float64" | "f64" => Ok(Dtype::Float64),
            other => Err(DtypeError::Unknown(other.to_owned())),
        }
    }

    /// Bytes per value.
    pub fn size(self) -> usize {
        match self {
            Dtype::Float32 => 4,
            Dtype::Float64 => 8,
        }
    }

    /// The `.npy` dtype string: little-endian.
    pub fn descr(self) -> &'static str {
        match self {
            Dtype::Float32 => "<f4",
            Dtype::Float64 => "<f8",
        }
    }

    /// Whether `method`'s weights can be stored in this dtype with the
    /// precision it promises.
    pub fn check_family(self, method: Method) -> Result<(), DtypeError> {
        match (self, method) {
            (Dtype::Float64, Method::Harmonic) => Err(DtypeError::Harmonic),
            (Dtype::Float64, method) if !method.spec().rows_independent => {
                Err(DtypeError::SampledFromGrid {
                    family: method.name(),
                })
            }
            _ => Ok(()),
        }
    }
}

/// A weight as stored: `f32` or `f64`, converted from the row computed in f64.
pub trait WeightValue: Copy + Default + Send + Sync + 'static {
    const DTYPE: Dtype;
    fn from_f64(value: f64) -> Self;
    fn to_f64(self) -> f64;
}

impl WeightValue for f32 {
    const DTYPE: Dtype = Dtype::Float32;
    fn from_f64(value: f64) -> Self {
        value as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

impl WeightValue for f64 {
    const DTYPE: Dtype = Dtype::Float64;
    fn from_f64(value: f64) -> Self {
        value
    }
    fn to_f64(self) -> f64 {
        self
    }
}

/// `rest` moved by `Σₖ wₖ dₖ` per row of the row-major `values` (`moves` one
/// displacement per column), accumulated in f64: the one deformation of every
/// weights matrix, whatever its dtype.
pub fn displaced<T: WeightValue>(values: &[T], rest: &[DVec3], moves: &[DVec3]) -> Vec<DVec3> {
    let cols = moves.len();
    values
        .par_chunks(cols.max(1))
        .take(rest.len())
        .zip(rest.par_iter())
        .map(|(row, &p)| {
            p + row
                .iter()
                .zip(moves)
                .map(|(&w, &d)| w.to_f64() * d)
                .sum::<DVec3>()
        })
        .collect()
}

/// Dense weights kept in float64: [`super::Weights`]' layout, one row per point,
/// row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct WeightsF64 {
    pub rows: usize,
    pub cols: usize,
    pub values: Vec<f64>,
}

impl WeightsF64 {
    pub fn zeros(rows: usize, cols: usize) -> Self {
        Self {
            rows,
            cols,
            values: vec![0.0; rows * cols],
        }
    }

    pub fn row(&self, row: usize) -> &[f64] {
        &self.values[row * self.cols..(row + 1) * self.cols]
    }

    /// As [`super::Weights::apply_displacements`].
    pub fn apply_displacements(&self, rest: &[DVec3], moves: &[DVec3]) -> Vec<DVec3> {
        assert_eq!(
            moves.len(),
            self.cols,
            "one displacement per weights column"
        );
        assert_eq!(rest.len(), self.rows, "one rest position per weights row");
        displaced(&self.values, rest, moves)
    }

    /// As [`super::Weights::apply_moves`].
    pub fn apply_moves(&self, rest: &[DVec3], moves: &super::ColumnMoves) -> Vec<DVec3> {
        assert_eq!(moves.len(), self.cols, "one move per weights column");
        assert_eq!(rest.len(), self.rows, "one rest position per weights row");
        moves.apply(&self.values, rest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_parser_names_every_dtype_and_refuses_the_rest() {
        for (text, dtype) in [
            ("float32", Dtype::Float32),
            ("f32", Dtype::Float32),
            ("float64", Dtype::Float64),
            ("f64", Dtype::Float64),
        ] {
            assert_eq!(Dtype::parse(text), Ok(dtype));
        }
        for dtype in [Dtype::Float32, Dtype::Float64] {
            assert_eq!(Dtype::parse(dtype.id()), Ok(dtype));
        }
        let error = Dtype::parse("float16").unwrap_err().to_string();
        assert_eq!(
            error,
            "dtype \"float16\" is not float32 or float64 (f32, f64)"
        );
        assert_eq!(
            Dtype::Float64.check_family(Method::Harmonic),
            Err(DtypeError::Harmonic)
        );
        for method in [Method::Mvc, Method::Pmvc, Method::Green] {
            assert_eq!(Dtype::Float64.check_family(method), Ok(()));
        }
    }
}
