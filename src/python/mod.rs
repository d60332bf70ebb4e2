//! The Python package `pmvc` (distribution `pmvc-cage`, feature `python`).
//!
//! Layout: the Rust side is this module, compiled into the extension module
//! `pmvc._native` (maturin builds the crate as a cdylib with
//! `cargo rustc --crate-type cdylib`, so ordinary builds never link one); the
//! Python side is `src/python/pmvc/`: `__init__.py` (the public names),
//! `_errors.py` (the exception classes, raised from here), `_native.pyi` (type
//! stubs) and `py.typed`. `pyproject.toml` at the top names both.
//!
//! - [`arrays`]: array-likes in (checked: shape, dtype, finite values, indices),
//!   numpy arrays out.
//! - [`scene`]: `Cage`, `load_mesh`, `classify`, `generate_cage`; [`families`]: `families`.
//! - [`binding`]: `bind` and `deform`, run off the GIL with progress and Ctrl-C.
//! - [`weights`]: the `Weights` class, `save_weights` and `load_weights`.
//! - [`errors`]: library errors as `pmvc.PmvcError` subclasses.
//!
//! Everything is checked by the library's own functions (`Cage::new`,
//! `BindOptions::validate`, the weights readers); nothing here re-implements a
//! family.

mod arguments;
mod arrays;
mod bind_arguments;
mod binding;
mod errors;
mod families;
mod scene;
mod weights;

use pyo3::prelude::*;

/// The compiled half of the `pmvc` package; import `pmvc`, not this.
#[pymodule]
fn _native(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_class::<scene::PyCage>()?;
    module.add_class::<weights::PyWeights>()?;
    module.add_function(wrap_pyfunction!(scene::load_mesh, module)?)?;
    module.add_function(wrap_pyfunction!(scene::restore_cage, module)?)?;
    module.add_function(wrap_pyfunction!(weights::restore_weights, module)?)?;
    module.add_function(wrap_pyfunction!(scene::classify, module)?)?;
    module.add_function(wrap_pyfunction!(scene::generate_cage, module)?)?;
    module.add_function(wrap_pyfunction!(families::families, module)?)?;
    module.add_function(wrap_pyfunction!(binding::bind, module)?)?;
    module.add_function(wrap_pyfunction!(binding::deform, module)?)?;
    module.add_function(wrap_pyfunction!(weights::save_weights, module)?)?;
    module.add_function(wrap_pyfunction!(weights::load_weights, module)?)?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
