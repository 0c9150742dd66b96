//! One state or a batch: arguments of shape `(n,)` or `(B, n)` checked and copied, a function of
//! one state evaluated on each (a batch across cores with rayon, the GIL released), results
//! returned as numpy arrays of shape `shape` or `(B, *shape)`.

use crate::{catch, to_py, KanegenError};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use rayon::prelude::*;

/// The most array arguments a function takes.
pub const MAX_ARGS: usize = 3;

/// An array argument as numpy gives it (any real dtype, converted to `float64`).
pub type Arg<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// The arguments of one call: each one's values (rows of its length, one per state).
pub struct States {
    /// Per argument, its values, `batch × len` (one row when not batched).
    values: Vec<Vec<f64>>,
    /// Per argument, its length.
    lens: Vec<usize>,
    /// `Some(B)` for 2-D arguments.
    batch: Option<usize>,
}

/// `expected shape (n,) or (B, n)` with the shape given.
fn shape_error(name: &str, n: usize, shape: &[usize]) -> PyErr {
    KanegenError::new_err(format!(
        "{name}: expected shape ({n},) or (B, {n}), got {}",
        tuple(shape)
    ))
}

/// A shape as Python writes it: `(3,)`, `(2, 3)`.
fn tuple(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
            format!("({})", parts.join(", "))
        }
    }
}

impl States {
    /// Checks `(name, array, expected length)` for each argument: 1-D of that length, or 2-D with
    /// that many columns and one batch size for all; every entry finite.
    ///
    /// # Errors
    /// A wrong shape, mixed 1-D and 2-D arguments, different batch sizes, a non-finite entry;
    /// each names the argument.
    pub fn new(args: &[(&str, &Arg<'_>, usize)]) -> PyResult<States> {
        assert!(args.len() <= MAX_ARGS, "at most {MAX_ARGS} array arguments");
        let mut batch: Option<Option<usize>> = None;
        let mut values = Vec::with_capacity(args.len());
        for &(name, a, n) in args {
            let shape = a.shape();
            let this = match shape {
                [m] if *m == n => None,
                [b, m] if *m == n => Some(*b),
                _ => return Err(shape_error(name, n, shape)),
            };
            match batch {
                None => batch = Some(this),
                Some(b) if b != this => {
                    return Err(KanegenError::new_err(format!(
                        "{name}: shape {} does not match the batch of the arguments \
                         before it ({})",
                        tuple(shape),
                        b.map_or("one state".to_string(), |b| format!("{b} states"))
                    )))
                }
                Some(_) => {}
            }
            let array = a.as_array();
            // A contiguous array (the usual case) is one copy; others are walked in order.
            let v: Vec<f64> = match array.as_slice() {
                Some(s) => s.to_vec(),
                None => array.iter().copied().collect(),
            };
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                let at = match this {
                    Some(_) => format!("[{}, {}]", k / n, k % n),
                    None => format!("[{k}]"),
                };
                return Err(KanegenError::new_err(format!(
                    "{name}{at} = {} is not finite",
                    v[k]
                )));
            }
            values.push(v);
        }
        Ok(States {
            values,
            lens: args.iter().map(|a| a.2).collect(),
            batch: batch.flatten(),
        })
    }

    /// Whether the arguments are a batch (2-D).
    pub fn is_batch(&self) -> bool {
        self.batch.is_some()
    }

    /// The rows of states `k..k + m` of each argument (at most [`MAX_ARGS`]; the rest empty).
    fn rows(&self, k: usize, m: usize) -> [&[f64]; MAX_ARGS] {
        let mut out: [&[f64]; MAX_ARGS] = [&[]; MAX_ARGS];
        for ((o, v), &n) in out.iter_mut().zip(&self.values).zip(&self.lens) {
            *o = &v[k * n..(k + m) * n];
        }
        out
    }

    /// `f(workspace, arguments of a state, output)` on every state, the outputs of shapes
    /// `shapes` written one after another into `output`; a batch across cores (one workspace
    /// per worker from `init`), the GIL released. Returns the arrays (a tuple when there are
    /// several).
    ///
    /// # Errors
    /// The first error of `f` (a batch's names its state), as a `KanegenError`.
    pub fn eval<'py, W>(
        &self,
        py: Python<'py>,
        shapes: &[&[usize]],
        init: impl Fn() -> W + Sync + Send,
        f: impl Fn(&mut W, &[&[f64]], &mut [f64]) -> anyhow::Result<()> + Sync + Send,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.eval_chunked(py, shapes, 1, init, |w, x, o| f(w, &x, o))
    }

    /// [`States::eval`] with `f` given up to `chunk` states at once: the rows of consecutive
    /// states of each argument and their outputs' rows.
    ///
    /// # Errors
    /// The first error of `f` (a batch's names its states), as a `KanegenError`.
    pub fn eval_chunked<'py, W>(
        &self,
        py: Python<'py>,
        shapes: &[&[usize]],
        chunk: usize,
        init: impl Fn() -> W + Sync + Send,
        f: impl Fn(&mut W, [&[f64]; MAX_ARGS], &mut [f64]) -> anyhow::Result<()> + Sync + Send,
    ) -> PyResult<Bound<'py, PyAny>> {
        let sizes: Vec<usize> = shapes.iter().map(|s| s.iter().product()).collect();
        let size: usize = sizes.iter().sum();
        let states = self.batch.unwrap_or(1);
        let mut out = vec![0.0; states * size];
        let run = |w: &mut W, c: usize, o: &mut [f64]| {
            let (k, m) = (c * chunk, o.len() / size.max(1));
            catch(|| f(w, self.rows(k, m), o)).map_err(|e| match (self.batch, m) {
                (None, _) => e,
                (Some(_), 1) => e.context(format!("state {k}")),
                (Some(_), _) => e.context(format!("states {k} to {}", k + m - 1)),
            })
        };
        py.allow_threads(|| match self.batch {
            None => run(&mut init(), 0, &mut out),
            Some(_) => out
                .par_chunks_mut(chunk * size.max(1))
                .with_min_len(64 / chunk)
                .enumerate()
                .try_for_each_init(&init, |w, (c, o)| run(w, c, o)),
        })
        .map_err(|e| to_py(&e))?;
        let dims = |shape: &[usize]| -> Vec<usize> {
            self.batch
                .into_iter()
                .chain(shape.iter().copied())
                .collect()
        };
        if let [shape] = shapes {
            // One output: the buffer is the array.
            let a = ArrayD::from_shape_vec(IxDyn(&dims(shape)), out).expect("sizes from the shape");
            return Ok(a.into_pyarray(py).into_any());
        }
        let mut arrays = Vec::with_capacity(shapes.len());
        let mut offset = 0;
        for (shape, n) in shapes.iter().zip(&sizes) {
            let data: Vec<f64> = (0..states)
                .flat_map(|k| {
                    out[k * size + offset..k * size + offset + n]
                        .iter()
                        .copied()
                })
                .collect();
            let a =
                ArrayD::from_shape_vec(IxDyn(&dims(shape)), data).expect("sizes from the shapes");
            arrays.push(a.into_pyarray(py).into_any());
            offset += n;
        }
        if arrays.len() == 1 {
            Ok(arrays.pop().expect("one array"))
        } else {
            Ok(PyTuple::new(py, arrays)?.into_any())
        }
    }
}
