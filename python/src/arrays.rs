//! Array-likes in: anything `numpy.asarray` accepts, checked for shape and dtype with a
//! message naming the argument, then copied into the flat vectors the Rust API takes (so
//! the scene can be built without the GIL, while Python goes on changing its arrays).

use crate::errors::{invalid, with_context};
use numpy::{PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyModule;

static NUMPY: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

fn numpy(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    NUMPY
        .get_or_try_init(py, || Ok::<_, PyErr>(py.import("numpy")?.unbind()))
        .map(|m| m.bind(py))
}

/// An array with its shape and dtype, as numpy sees it.
pub struct Array<'py> {
    array: Bound<'py, PyAny>,
    pub shape: Vec<usize>,
    /// numpy's dtype kind: `f` float, `i` signed, `u` unsigned integer, `b` bool, …
    kind: char,
    itemsize: usize,
    dtype: String,
}

impl<'py> Array<'py> {
    pub fn new(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Self> {
        let py = obj.py();
        let array = numpy(py)?
            .call_method1("asarray", (obj,))
            .map_err(|e| with_context(py, e, &format!("{name} is not an array")))?;
        let dtype = array.getattr("dtype")?;
        let kind: String = dtype.getattr("kind")?.extract()?;
        Ok(Array {
            shape: array.getattr("shape")?.extract()?,
            kind: kind.chars().next().unwrap_or('?'),
            itemsize: dtype.getattr("itemsize")?.extract()?,
            dtype: dtype.str()?.to_string(),
            array,
        })
    }

    /// The shape as Python writes it: `(4, 2)`, `(12,)`.
    pub fn shape_text(&self) -> String {
        match &self.shape[..] {
            [n] => format!("({n},)"),
            shape => {
                let sides: Vec<String> = shape.iter().map(usize::to_string).collect();
                format!("({})", sides.join(", "))
            }
        }
    }

    fn len(&self) -> usize {
        self.shape.iter().product()
    }

    /// Checks the shape against `expected` (`None`: any length on that axis), describing
    /// the expectation as `what` in the error.
    pub fn check_shape(&self, name: &str, expected: &[Option<usize>], what: &str) -> PyResult<()> {
        let matches = self.shape.len() == expected.len()
            && self
                .shape
                .iter()
                .zip(expected)
                .all(|(&n, e)| e.is_none_or(|e| e == n));
        // An empty list is no vertices (or no triangles), whatever its columns.
        if matches || (self.len() == 0 && self.shape.len() == 1) {
            Ok(())
        } else {
            Err(invalid(
                self.array.py(),
                &format!("{name} has shape {}; expected {what}", self.shape_text()),
            ))
        }
    }

    /// The values as float32 (from any float or integer dtype; a float64 beyond float32's
    /// range becomes infinite, which the Rust API then rejects naming the element).
    pub fn to_f32(&self, name: &str) -> PyResult<Vec<f32>> {
        if !matches!(self.kind, 'f' | 'i' | 'u') {
            return Err(invalid(
                self.array.py(),
                &format!(
                    "{name} has dtype {}; expected numbers (float32 or convertible to it)",
                    self.dtype
                ),
            ));
        }
        self.contiguous::<f32>("float32")
    }

    /// The values as uint32: from integer dtypes only (a float index would be truncated
    /// silently), each in [0, 2^32).
    pub fn to_u32(&self, name: &str) -> PyResult<Vec<u32>> {
        let py = self.array.py();
        if !matches!(self.kind, 'i' | 'u') {
            return Err(invalid(
                py,
                &format!(
                    "{name} has dtype {}; expected integers (uint32 or convertible to it without loss)",
                    self.dtype
                ),
            ));
        }
        if self.len() > 0 {
            for (extreme, arg) in [("min", "argmin"), ("max", "argmax")] {
                let value: i128 = self.array.call_method0(extreme)?.extract()?;
                if !(0..=u32::MAX as i128).contains(&value) {
                    let flat: usize = self.array.call_method0(arg)?.extract()?;
                    return Err(invalid(
                        py,
                        &format!(
                            "{name}{} is {value}; it must be in [0, 2^32 - 1]",
                            self.position(flat)
                        ),
                    ));
                }
            }
        }
        self.contiguous::<u32>("uint32")
    }

    /// The values as 8-bit integers if the dtype is one byte unsigned, else `None`.
    pub fn to_u8(&self) -> PyResult<Option<Vec<u8>>> {
        if self.kind == 'u' && self.itemsize == 1 {
            self.contiguous::<u8>("uint8").map(Some)
        } else {
            Ok(None)
        }
    }

    /// `[row, column]` of the element at `flat` in C order.
    fn position(&self, flat: usize) -> String {
        let mut index = Vec::with_capacity(self.shape.len());
        let mut rest = flat;
        for &n in self.shape.iter().rev() {
            index.push(rest % n.max(1));
            rest /= n.max(1);
        }
        index.reverse();
        format!("{index:?}")
    }

    fn contiguous<T: numpy::Element + Copy>(&self, dtype: &str) -> PyResult<Vec<T>> {
        let np = numpy(self.array.py())?;
        let converted = np.call_method1("ascontiguousarray", (&self.array, np.getattr(dtype)?))?;
        let converted = converted.cast_into::<PyArrayDyn<T>>()?;
        Ok(converted.readonly().as_slice()?.to_vec())
    }
}

/// An (N, `columns`) array of numbers as a flat float32 vector.
pub fn rows_f32(obj: &Bound<'_, PyAny>, name: &str, columns: usize) -> PyResult<Vec<f32>> {
    let array = Array::new(obj, name)?;
    array.check_shape(
        name,
        &[None, Some(columns)],
        &format!("(N, {columns}) with N rows of {columns} numbers"),
    )?;
    array.to_f32(name)
}

/// An (M, 3) array of vertex indices as a flat uint32 vector.
pub fn triangles_u32(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<u32>> {
    let array = Array::new(obj, name)?;
    array.check_shape(
        name,
        &[None, Some(3)],
        "(M, 3) with one row of three vertex indices per triangle",
    )?;
    array.to_u32(name)
}

/// A one-dimensional array of integers as uint32.
pub fn vector_u32(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<u32>> {
    let array = Array::new(obj, name)?;
    array.check_shape(name, &[None], "(M,) with one entry per triangle")?;
    array.to_u32(name)
}
