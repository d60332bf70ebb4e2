//! Weights, their class mask and their metadata written and read as one set.

use super::classes::{classes_path, read_classes_npy, write_classes_npy_to};
use super::*;

/// Write weights, their class mask and their metadata together: all three
/// replace their files, or none does ([`OutputSet`]). Green coordinates go to a
/// `.npz` (φ and ψ), the rest to a `.npy`.
pub fn save_weights_set(
    path: &Path,
    weights: &Weights,
    metadata: &WeightsMetadata,
    classes: &[i8],
) -> Result<(), MetadataError> {
    save_values(
        path,
        (&weights.values, weights.rows, weights.cols),
        metadata,
        classes,
    )
}

/// [`save_weights_set`] of weights of either dtype; the metadata's `dtype`
/// must be theirs.
pub fn save_any_weights_set(
    path: &Path,
    weights: &AnyWeights,
    metadata: &WeightsMetadata,
    classes: &[i8],
) -> Result<(), MetadataError> {
    match weights {
        AnyWeights::F32(weights) => save_weights_set(path, weights, metadata, classes),
        AnyWeights::F64(weights) => save_values(
            path,
            (&weights.values, weights.rows, weights.cols),
            metadata,
            classes,
        ),
    }
}

fn save_values<T: LeBytes>(
    path: &Path,
    (values, rows, cols): (&[T], usize, usize),
    metadata: &WeightsMetadata,
    classes: &[i8],
) -> Result<(), MetadataError> {
    if metadata.dtype() != T::DTYPE || metadata.dtype != T::DTYPE.id() {
        return Err(MetadataError::Field {
            path: path.to_owned(),
            field: "dtype",
            reason: format!(
                "{:?} in the metadata, but the weights are {}",
                metadata.dtype,
                T::DTYPE.id()
            ),
        });
    }
    if classes.len() != rows || metadata.rows != rows {
        return Err(MetadataError::Field {
            path: path.to_owned(),
            field: "rows",
            reason: format!(
                "{rows} weights rows, {} classes and {} rows in the metadata",
                classes.len(),
                metadata.rows
            ),
        });
    }
    let outputs = OutputSet::create(&[path, &classes_path(path), &metadata_path(path)])?;
    let preamble = npy_preamble_of(path, rows, cols, T::DTYPE)?;
    let json = metadata.to_json_pretty();
    let npz = metadata.columns_layout == layout_id(ColumnLayout::CageVerticesThenTriangles);
    outputs.finish_seekable(|index, out| match index {
        0 if npz => write_npz_values(out, path, (values, cols), metadata.cage.vertices),
        0 => {
            out.write_all(&preamble)?;
            write_values(out, values)
        }
        1 => write_classes_npy_to(out, classes),
        _ => out.write_all(json.as_bytes()),
    })?;
    Ok(())
}

/// Weights read back with what was written beside them.
pub struct LoadedWeights {
    pub weights: Weights,
    pub metadata: WeightsMetadata,
    pub options: BindOptions,
    pub classes: Vec<i8>,
}

/// [`LoadedWeights`] of either dtype.
pub struct LoadedAnyWeights {
    pub weights: AnyWeights,
    pub metadata: WeightsMetadata,
    pub options: BindOptions,
    pub classes: Vec<i8>,
}

/// The float32 weights of a set: [`load_any_weights_set`], refusing float64.
pub fn load_weights_set(path: &Path) -> Result<LoadedWeights, MetadataError> {
    let loaded = load_any_weights_set(path)?;
    match loaded.weights {
        AnyWeights::F32(weights) => Ok(LoadedWeights {
            weights,
            metadata: loaded.metadata,
            options: loaded.options,
            classes: loaded.classes,
        }),
        AnyWeights::F64(_) => Err(MetadataError::Field {
            path: metadata_path(path),
            field: "dtype",
            reason: "is float64, and this reader takes float32 weights".to_owned(),
        }),
    }
}

/// Read weights written by [`save_weights_set`] or `pmvc bind`: the metadata
/// first, then the arrays with the shapes it states (checked as `pmvc deform
/// --weights` checks them: finite values, cage-vertex rows summing to 1 within
/// [`super::npy::ROW_SUM_TOLERANCE`]), then the class mask. The matrix is float32
/// or float64, as the metadata's `dtype` says.
pub fn load_any_weights_set(path: &Path) -> Result<LoadedAnyWeights, MetadataError> {
    let json = metadata_path(path);
    if !json.exists() {
        return Err(MetadataError::Read {
            path: json,
            source: std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!(
                    "no metadata beside {}: weights are read with the JSON `pmvc bind` writes next to them",
                    shown_path(path)
                ),
            ),
        });
    }
    let metadata = read_metadata(&json)?;
    let options = metadata.check_consistent(&json)?;
    let (rows, vertices, triangles) = (
        metadata.rows,
        metadata.cage.vertices,
        metadata.face_columns(),
    );
    let npz = options.method.spec().columns == ColumnLayout::CageVerticesThenTriangles;
    let expected = ExpectedArray::of_layout(
        options.method.spec().columns,
        rows,
        vertices,
        metadata.cage.triangles,
    );
    let weights = match (metadata.dtype(), npz) {
        (Dtype::Float32, true) => AnyWeights::F32(read_npz(path, rows, vertices, triangles)?),
        (Dtype::Float32, false) => AnyWeights::F32(read_npy(path, expected)?),
        (Dtype::Float64, true) => AnyWeights::F64(read_npz_f64(path, rows, vertices, triangles)?),
        (Dtype::Float64, false) => AnyWeights::F64(read_npy_f64(path, expected)?),
    };
    // A bare file name beside the weights: the metadata never points elsewhere.
    let name = Path::new(&metadata.classes.file);
    if name.file_name() != Some(name.as_os_str()) {
        return Err(MetadataError::Field {
            path: json,
            field: "classes.file",
            reason: format!(
                "{:?} is not a file name beside the weights",
                metadata.classes.file
            ),
        });
    }
    let classes_file = path.with_file_name(name);
    let classes = read_classes_npy(&classes_file, rows)?;
    Ok(LoadedAnyWeights {
        weights,
        metadata,
        options,
        classes,
    })
}
