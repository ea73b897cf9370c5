//! `lineao._lineao`: the compiled half of the Python package `lineao` (its Python half,
//! `python/lineao/__init__.py`, converts nibabel's and DIPY's objects and documents the API).
//!
//! - **Loading** hands numpy the loaders' own buffers: a `Vec` becomes an array's memory
//!   without a copy (the array's `base` is the Rust allocation), and the GIL is released while
//!   the file is read; the progress callback takes the GIL back every 4 MiB to check for
//!   Ctrl-C, which cancels the load (`KeyboardInterrupt`).
//! - **Rendering** takes `lineao render`'s options as keyword arguments (the names with `_` for
//!   `-`), typed: they deserialize into the command line's own arguments
//!   (`RenderArgs::from_keywords`), each value parsed as its option parses it, with the same
//!   defaults and checks and errors that name the keyword — no command line is built. The
//!   picture is the binary's pixel for pixel: [`Renderer`] holds a `lineao_session` render session
//!   (device, geometry on the GPU, one chain per panel) for many frames.

use std::ops::ControlFlow;
use std::path::PathBuf;

use lineao_session::args::RenderArgs;
use lineao_session::kwargs::KwargError;
use lineao_session::render::Session;
use lineao_session::source::Loaded;
use lineao_tracts::{Field, Group, Tractogram, VoxelSpace};
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

create_exception!(
    _lineao,
    LoadError,
    PyValueError,
    "A file could not be loaded or saved: `file`, `offset` (the byte, or None) and `expected` (what the \
     format requires there, or None) say where and why."
);

/// The Python exception of a loader's error: `KeyboardInterrupt` for a cancelled load, else a
/// `LoadError` carrying the file, the byte offset and the expectation.
fn load_error(py: Python<'_>, error: lineao_tracts::Error) -> PyErr {
    if matches!(error.kind, lineao_tracts::ErrorKind::Cancelled) {
        return PyKeyboardInterrupt::new_err(error.to_string());
    }
    let expected = match &error.kind {
        lineao_tracts::ErrorKind::Format { expected, .. } => Some(expected.clone()),
        _ => None,
    };
    let err = LoadError::new_err(error.to_string());
    let value = err.value(py);
    // Setting attributes on a fresh exception cannot fail.
    let _ = value.setattr("file", error.path.display().to_string());
    let _ = value.setattr("offset", error.kind.offset());
    let _ = value.setattr("expected", expected);
    err
}

/// `Vec<[f32; 3]>` as the flat `Vec<f32>` of its coordinates, in the same allocation.
fn flatten(points: Vec<[f32; 3]>) -> Vec<f32> {
    let mut points = std::mem::ManuallyDrop::new(points);
    let (ptr, len, cap) = (points.as_mut_ptr(), points.len(), points.capacity());
    // SAFETY: [f32; 3] and f32 have the same alignment, and an allocation of `cap` [f32; 3]
    // is one of `3 cap` f32 (the same size and layout), so the Vec may own it as f32.
    unsafe { Vec::from_raw_parts(ptr.cast::<f32>(), 3 * len, 3 * cap) }
}

/// A field's values as (rows, columns) float32, or (rows,) for one column, without a copy.
fn field_array(py: Python<'_>, field: Field) -> PyResult<Bound<'_, PyAny>> {
    if field.columns <= 1 {
        return Ok(field.values.into_pyarray(py).into_any());
    }
    let rows = field.values.len() / field.columns;
    let array = Array2::from_shape_vec((rows, field.columns), field.values)
        .map_err(|e| PyValueError::new_err(format!("field '{}': {e}", field.name)))?;
    Ok(array.into_pyarray(py).into_any())
}

/// Loads `path` with the GIL released; `progress` is None, True (a bar on a terminal) or a
/// callable(bytes, total). Returns the tractogram's parts as a dict of arrays.
#[pyfunction]
#[pyo3(signature = (path, progress = None))]
fn load<'py>(py: Python<'py>, path: PathBuf, progress: Option<Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyDict>> {
    // True: a bar on a terminal (as the CLI's, for files over 32 MiB); a callable: called.
    let wants_bar = progress.as_ref().is_some_and(|p| !p.is_callable() && p.is_truthy().unwrap_or(false));
    let callback = progress.filter(|p| p.is_callable()).map(Bound::unbind);
    let bar = if wants_bar { lineao_session::source::progress_bar(&path) } else { None };
    let mut interrupted: Option<PyErr> = None;
    let loaded = py.detach(|| {
        let mut report = |p: lineao_tracts::Progress| {
            if let Some(bar) = &bar {
                bar.set_position(p.bytes);
            }
            Python::attach(|py| {
                let result = py.check_signals().and_then(|()| match &callback {
                    Some(f) => f.call1(py, (p.bytes, p.total)).map(drop),
                    None => Ok(()),
                });
                match result {
                    Ok(()) => ControlFlow::Continue(()),
                    Err(e) => {
                        interrupted = Some(e);
                        ControlFlow::Break(())
                    }
                }
            })
        };
        lineao_tracts::load_with(&path, &Default::default(), Some(&mut report))
    });
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    if let Some(e) = interrupted {
        return Err(e);
    }
    let loaded = loaded.map_err(|e| load_error(py, e))?;
    tractogram_dict(py, loaded.tractogram, loaded.format.name())
}

/// The parts of `t` as arrays that own the loader's memory (points, offsets, fields).
fn tractogram_dict<'py>(py: Python<'py>, t: Tractogram, format: &str) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let (n, streamlines) = (t.positions.len(), t.streamlines());
    let lengths: Vec<i64> = t.offsets.windows(2).map(|w| (w[1] - w[0]) as i64).collect();
    let mut offsets = t.offsets;
    offsets.truncate(streamlines);
    let offsets: Vec<i64> = bytemuck::allocation::cast_vec(offsets);
    let points = Array2::from_shape_vec((n, 3), flatten(t.positions)).expect("3 coordinates a point");
    dict.set_item("points", points.into_pyarray(py))?;
    dict.set_item("offsets", offsets.into_pyarray(py))?;
    dict.set_item("lengths", lengths.into_pyarray(py))?;
    let fields = |fields: Vec<Field>| -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for field in fields {
            dict.set_item(field.name.clone(), field_array(py, field)?)?;
        }
        Ok(dict)
    };
    dict.set_item("vertex_fields", fields(t.vertex_fields)?)?;
    dict.set_item("streamline_fields", fields(t.streamline_fields)?)?;
    let groups = PyDict::new(py);
    for group in t.groups {
        groups.set_item(group.name, group.streamlines.into_pyarray(py))?;
    }
    dict.set_item("groups", groups)?;
    if let Some(space) = t.space {
        let affine = Array2::from_shape_fn((4, 4), |(i, j)| space.affine[i][j]);
        dict.set_item("affine", affine.into_pyarray(py))?;
        dict.set_item("dimensions", PyTuple::new(py, space.dimensions)?)?;
        dict.set_item("voxel_sizes", space.voxel_sizes.map(|v| PyTuple::new(py, v)).transpose()?)?;
    } else {
        dict.set_item("affine", py.None())?;
        dict.set_item("dimensions", py.None())?;
        dict.set_item("voxel_sizes", py.None())?;
    }
    dict.set_item("format", format)?;
    Ok(dict)
}

/// The NIfTI volume at `path` sampled at `points` (N, 3, RAS+ mm): trilinear between voxel
/// centres, NaN outside (`lineao_tracts::Volume::sample`), what `--color volume:FILE` draws.
#[pyfunction]
fn sample_volume<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f32>,
    path: PathBuf,
) -> PyResult<Bound<'py, numpy::PyArray1<f32>>> {
    let volume = py.detach(|| lineao_tracts::Volume::load(&path)).map_err(|e| load_error(py, e))?;
    let points: &[[f32; 3]] = bytemuck::cast_slice(points.as_slice()?);
    let values = py.detach(|| volume.sample_points(points));
    Ok(values.into_pyarray(py))
}

/// `lineao info --json` of `path`, as its JSON text (docs/reference.md's keys).
#[pyfunction]
fn info(py: Python<'_>, path: PathBuf) -> PyResult<String> {
    let loaded = py.detach(|| lineao_tracts::load(&path)).map_err(|e| load_error(py, e))?;
    Ok(lineao_session::info::describe(&loaded).to_string())
}

/// Streamlines handed over from Python: points (N, 3) float32 C-contiguous, and per
/// streamline its first point and its length (int64), in any order (nibabel's selections
/// share points with offsets out of order).
struct Streamlines<'py> {
    points: PyReadonlyArray2<'py, f32>,
    offsets: PyReadonlyArray1<'py, i64>,
    lengths: PyReadonlyArray1<'py, i64>,
}

impl<'py> Streamlines<'py> {
    fn extract(points: &Bound<'py, PyAny>, offsets: &Bound<'py, PyAny>, lengths: &Bound<'py, PyAny>) -> PyResult<Self> {
        let points: PyReadonlyArray2<'py, f32> = points.extract().map_err(|_| {
            PyTypeError::new_err("points: expected a 2-D numpy array of float32 (lineao converts other inputs first)")
        })?;
        let offsets: PyReadonlyArray1<'py, i64> =
            offsets.extract().map_err(|_| PyTypeError::new_err("offsets: expected a 1-D numpy array of int64"))?;
        let lengths: PyReadonlyArray1<'py, i64> =
            lengths.extract().map_err(|_| PyTypeError::new_err("lengths: expected a 1-D numpy array of int64"))?;
        if points.shape()[1] != 3 {
            return Err(PyValueError::new_err(format!("points: expected shape (N, 3), got {:?}", points.shape())));
        }
        if !points.is_c_contiguous() {
            return Err(PyValueError::new_err("points: expected a C-contiguous array"));
        }
        if offsets.len() != lengths.len() {
            let (o, l) = (offsets.len(), lengths.len());
            return Err(PyValueError::new_err(format!("offsets ({o}) and lengths ({l}) differ in length")));
        }
        Ok(Streamlines { points, offsets, lengths })
    }

    /// The streamlines gathered into a `Tractogram` (the GPU upload and the ray tracer read
    /// it), checked against the points; called with the GIL released.
    fn gather(points: &[f32], offsets: &[i64], lengths: &[i64]) -> Result<Tractogram, String> {
        let n = points.len() / 3;
        let mut t = Tractogram::new();
        let total: i64 = lengths.iter().map(|&l| l.max(0)).sum();
        t.positions.reserve(total.min(n as i64 * 4) as usize);
        t.offsets.reserve(offsets.len());
        for (i, (&start, &length)) in offsets.iter().zip(lengths).enumerate() {
            let end = start.checked_add(length).filter(|&e| start >= 0 && length >= 0 && e <= n as i64);
            let Some(end) = end else {
                return Err(format!("streamline {i}: offset {start} and length {length} are outside the {n} points"));
            };
            let coords = &points[3 * start as usize..3 * end as usize];
            t.push(coords.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        }
        Ok(t)
    }
}

/// A tractogram from Python's arrays: the streamlines gathered in their order, their per-vertex
/// and per-streamline fields and groups.
fn tractogram_of(
    py: Python<'_>,
    points: &Bound<'_, PyAny>,
    offsets: &Bound<'_, PyAny>,
    lengths: &Bound<'_, PyAny>,
    vertex_fields: &Bound<'_, PyDict>,
    streamline_fields: &Bound<'_, PyDict>,
    groups: &Bound<'_, PyDict>,
) -> PyResult<Tractogram> {
    let lines = Streamlines::extract(points, offsets, lengths)?;
    let (p, o, l) = (lines.points.as_slice()?, lines.offsets.as_slice()?, lines.lengths.as_slice()?);
    let mut t = py.detach(|| Streamlines::gather(p, o, l)).map_err(PyValueError::new_err)?;
    let field = |name: String, values: &Bound<'_, PyAny>, rows: usize, what: &str| -> PyResult<Field> {
        let values: numpy::PyReadonlyArrayDyn<'_, f32> = values
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("{what} '{name}': expected a float32 numpy array")))?;
        let columns = if values.ndim() == 1 { 1 } else { values.shape()[1] };
        if values.ndim() > 2 || values.shape()[0] != rows {
            let shape = values.shape().to_vec();
            return Err(PyValueError::new_err(format!("{what} '{name}': expected {rows} rows, got shape {shape:?}")));
        }
        Ok(Field { name, columns, values: values.as_array().iter().copied().collect() })
    };
    // Per-vertex rows follow the points: gathered in the streamlines' order, as the points were.
    for (name, values) in vertex_fields {
        let Field { name, columns, values } = field(name.extract()?, &values, p.len() / 3, "vertex field")?;
        let values = o
            .iter()
            .zip(l)
            .flat_map(|(&start, &length)| &values[columns * start as usize..columns * (start + length) as usize])
            .copied()
            .collect();
        t.vertex_fields.push(Field { name, columns, values });
    }
    for (name, values) in streamline_fields {
        t.streamline_fields.push(field(name.extract()?, &values, t.streamlines(), "streamline field")?);
    }
    for (name, members) in groups {
        let members: Vec<u32> = members.extract()?;
        t.groups.push(Group { name: name.extract()?, streamlines: members, data: Vec::new() });
    }
    Ok(t)
}

/// Which of the streamlines `select`'s `rules` (keywords of `render`'s selection: `subset`,
/// `subset_seed`, `length`, `field`, `groups`, `include`, `exclude`) keep, one bool each
/// (`lineao_tracts::Selection::mask`: what `render` draws with the same keywords).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn select<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    offsets: &Bound<'py, PyAny>,
    lengths: &Bound<'py, PyAny>,
    streamline_fields: &Bound<'py, PyDict>,
    groups: &Bound<'py, PyDict>,
    rules: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, numpy::PyArray1<bool>>> {
    let known = lineao_session::args::SelectArgs::keywords();
    for key in rules.keys() {
        let key: String = key.extract()?;
        if !known.contains(&key) {
            let message = format!("unexpected keyword argument '{key}'; the rules are: {}", known.join(", "));
            return Err(PyTypeError::new_err(message));
        }
    }
    let args = parse(rules, None)?;
    let t = tractogram_of(py, points, offsets, lengths, &PyDict::new(py), streamline_fields, groups)?;
    let mask = match args.select.selection() {
        Some(selection) => py.detach(|| selection.mask(&t)).map_err(|e| PyValueError::new_err(e.to_string()))?,
        None => vec![true; t.streamlines()],
    };
    Ok(mask.into_pyarray(py))
}

/// Saves streamlines (points, offsets, lengths) with their fields, groups and voxel space as
/// `.tck`, `.trk` or `.trx` (by the extension); returns the names of fields the format dropped.
#[pyfunction]
#[pyo3(signature = (path, points, offsets, lengths, vertex_fields, streamline_fields, groups, affine=None, dimensions=None, voxel_sizes=None))]
#[allow(clippy::too_many_arguments)]
fn save(
    py: Python<'_>,
    path: PathBuf,
    points: &Bound<'_, PyAny>,
    offsets: &Bound<'_, PyAny>,
    lengths: &Bound<'_, PyAny>,
    vertex_fields: &Bound<'_, PyDict>,
    streamline_fields: &Bound<'_, PyDict>,
    groups: &Bound<'_, PyDict>,
    affine: Option<PyReadonlyArray2<'_, f64>>,
    dimensions: Option<[u32; 3]>,
    voxel_sizes: Option<[f32; 3]>,
) -> PyResult<Vec<String>> {
    let mut t = tractogram_of(py, points, offsets, lengths, vertex_fields, streamline_fields, groups)?;
    if let (Some(affine), Some(dimensions)) = (affine, dimensions) {
        let a = affine.as_array();
        if a.shape() != [4, 4] {
            return Err(PyValueError::new_err(format!("affine: expected shape (4, 4), got {:?}", a.shape())));
        }
        let affine = std::array::from_fn(|i| std::array::from_fn(|j| a[[i, j]]));
        t.space = Some(VoxelSpace { affine, dimensions, voxel_sizes });
    }
    py.detach(|| lineao_tracts::save(&t, &path)).map_err(|e| load_error(py, e))
}

/// A Python value as JSON for [`RenderArgs::from_keywords`]: `None`, bools, numbers (numpy's
/// scalars through `.item()`), strings and paths, sequences and dicts.
fn to_json(value: &Bound<'_, PyAny>) -> PyResult<serde_json::Value> {
    use serde_json::Value;
    if value.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = value.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if value.is_instance_of::<PyInt>() {
        let n: i128 = value.extract()?;
        return Ok(i64::try_from(n)
            .map(Value::from)
            .or_else(|_| u64::try_from(n).map(Value::from))
            .unwrap_or(Value::Null));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(serde_json::Number::from_f64(value.extract()?).map_or(Value::Null, Value::Number));
    }
    if let Ok(s) = value.cast::<PyString>() {
        return Ok(Value::String(s.to_cow()?.into_owned()));
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut map = serde_json::Map::new();
        for (k, v) in dict {
            map.insert(k.str()?.to_string(), to_json(&v)?);
        }
        return Ok(Value::Object(map));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        return value.try_iter()?.map(|item| to_json(&item?)).collect::<PyResult<_>>().map(Value::Array);
    }
    // numpy scalars and 0-d arrays, then paths.
    if value.hasattr("item")? && value.hasattr("dtype")? {
        return to_json(&value.call_method0("item")?);
    }
    if value.hasattr("__fspath__")? {
        return to_json(&value.call_method0("__fspath__")?);
    }
    Ok(Value::String(value.str()?.to_string()))
}

/// `render`'s arguments from keyword arguments, typed as the library's settings are
/// ([`RenderArgs::from_keywords`]): `None` leaves a keyword out; an unknown one is a
/// `TypeError` listing the known ones, a bad value a `ValueError` naming its keyword.
fn parse(settings: &Bound<'_, PyDict>, file: Option<&PathBuf>) -> PyResult<RenderArgs> {
    let mut values = serde_json::Map::new();
    for (key, value) in settings {
        if !value.is_none() {
            values.insert(key.extract()?, to_json(&value)?);
        }
    }
    let mut args = RenderArgs::from_keywords(values).map_err(|e| match e {
        KwargError::Unknown { .. } => PyTypeError::new_err(e.to_string()),
        KwargError::Invalid(_) => PyValueError::new_err(e.to_string()),
    })?;
    args.file = file.cloned();
    if args.figure.turntable.is_some() {
        return Err(PyValueError::new_err(
            "'turntable' is the command line's: Renderer.orbit(n_frames, movie=...) renders a turntable",
        ));
    }
    if args.style.tube_radius_field.is_some() && args.file.is_none() {
        return Err(PyValueError::new_err("'tube_radius_field' needs a file"));
    }
    Ok(args)
}

/// The settings `render` takes, each as (name, help, default): for the Python docs and
/// `lineao.settings()`, read from the command line's definition.
#[pyfunction]
fn settings() -> Vec<(String, String, Option<String>)> {
    RenderArgs::keywords().into_iter().map(|k| (k.name, k.help, k.default)).collect()
}

/// The method names `render` accepts (`method=`, `compare=`): the registry's (the ray-traced
/// truth among them), then the object-space ones and their sums with LineAO.
#[pyfunction]
fn methods() -> Vec<String> {
    let mut names: Vec<String> = lineao::AoMethod::REGISTRY.iter().map(|m| m.name().to_string()).collect();
    for method in lineao_session::args::Method::all() {
        if !names.contains(&method.name()) {
            names.push(method.name());
        }
    }
    names
}

/// A render session: the device, the streamlines on the GPU and one chain per panel, kept
/// for many frames. Made by `lineao.Renderer`; `render(settings)` returns (H, W, 4) uint8.
#[pyclass(module = "lineao._lineao")]
struct Renderer {
    session: Session,
    chains: Vec<lineao::AoChain>,
    /// What the session was opened with: what later frames may not change.
    opened: RenderArgs,
}

/// A `RuntimeError` with the whole chain of causes (`lineao: error: …` on the command line),
/// or a `ValueError` for settings the library refuses.
fn render_error(e: anyhow::Error) -> PyErr {
    let text = format!("{e:#}");
    if e.chain().any(|c| {
        matches!(
            c.downcast_ref::<lineao::Error>(),
            Some(lineao::Error::Conflict { .. } | lineao::Error::OutOfRange { .. })
        )
    }) {
        PyValueError::new_err(text)
    } else {
        PyRuntimeError::new_err(text)
    }
}

#[pymethods]
impl Renderer {
    /// Opens a session on `path` (a file `lineao info` reads; None: the built-in `scene`) or on
    /// streamlines (points, offsets, lengths) named `name`, with `settings` (a dict of
    /// render's keyword arguments). Device and upload run with the GIL released.
    ///
    /// Streamlines come with their fields and groups (`data`: per-vertex fields,
    /// per-streamline fields, groups), which colour (`color="field:NAME"`, `"groups"`) and
    /// select them.
    #[new]
    #[pyo3(signature = (settings, path=None, points=None, offsets=None, lengths=None, name="streamlines".to_string(), data=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        settings: &Bound<'_, PyDict>,
        path: Option<PathBuf>,
        points: Option<&Bound<'_, PyAny>>,
        offsets: Option<&Bound<'_, PyAny>>,
        lengths: Option<&Bound<'_, PyAny>>,
        name: String,
        data: Option<(Bound<'_, PyDict>, Bound<'_, PyDict>, Bound<'_, PyDict>)>,
    ) -> PyResult<Renderer> {
        let args = parse(settings, path.as_ref())?;
        let session = match (points, offsets, lengths) {
            (Some(points), Some(offsets), Some(lengths)) => {
                let empty = || PyDict::new(py);
                let (vertex, streamline, groups) = data.unwrap_or_else(|| (empty(), empty(), empty()));
                let tracts = tractogram_of(py, points, offsets, lengths, &vertex, &streamline, &groups)?;
                py.detach(|| -> PyResult<Session> {
                    if !tracts.positions.iter().flatten().any(|c| c.is_finite()) {
                        return Err(PyValueError::new_err(format!("{name} has no finite points")));
                    }
                    // Framed as a file of the same streamlines is (by their bounds on the GPU).
                    Session::with_loaded(&args, Loaded { name, tracts, hint: None }).map_err(render_error)
                })?
            }
            // Later frames may ask for any method: the points stay.
            _ => py.detach(|| Session::open_with_points(&args)).map_err(|e| match e
                .downcast::<lineao_session::source::SourceError>()
            {
                Ok(lineao_session::source::SourceError::Load(load)) => load_error(py, load),
                Ok(other) => render_error(other.into()),
                Err(e) => render_error(e),
            })?,
        };
        Ok(Renderer { session, chains: Vec::new(), opened: args })
    }

    /// Renders with `settings` (the session's, with a camera or methods of this frame): the
    /// picture as (height, width, 4) uint8, sRGB with alpha.
    fn render<'py>(&mut self, py: Python<'py>, settings: &Bound<'py, PyDict>) -> PyResult<Bound<'py, PyAny>> {
        let args = self.frame_args(settings)?;
        let (session, chains) = (&mut self.session, &mut self.chains);
        let (image, _) = py.detach(|| session.compose(&args, chains)).map_err(render_error)?;
        let (w, h) = (image.width as usize, image.height as usize);
        let array = Array3::from_shape_vec((h, w, 4), image.data).expect("4 bytes a pixel");
        Ok(array.into_pyarray(py).into_any())
    }

    /// `lineao score --json` on this session's view: each of `methods` (None: all) against
    /// the ray-traced truth, as the JSON text of docs/reference.md's `score --json`.
    #[pyo3(signature = (settings, methods=None))]
    fn score(
        &mut self,
        py: Python<'_>,
        settings: &Bound<'_, PyDict>,
        methods: Option<Vec<String>>,
    ) -> PyResult<String> {
        let args = self.frame_args(settings)?;
        let methods = match methods {
            None => lineao_session::args::ScoreMethod::all(),
            Some(names) => names
                .iter()
                .map(|n| {
                    lineao_session::args::parse_score_method(n)
                        .map_err(|e| PyValueError::new_err(format!("methods: {e}")))
                })
                .collect::<PyResult<_>>()?,
        };
        let session = &self.session;
        py.detach(|| {
            let report =
                lineao_session::score::score(session, &args, &methods, lineao_session::score::BUNDLE_DISTANCE)?;
            anyhow::Ok(lineao_session::score::to_json(session, &args, &report).to_string())
        })
        .map_err(render_error)
    }

    /// The camera of the last frame: eye, target, up, and fov (degrees) or ortho (height).
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let camera = &self.session.camera;
        let dict = PyDict::new(py);
        dict.set_item("eye", PyTuple::new(py, camera.eye.to_array())?)?;
        dict.set_item("target", PyTuple::new(py, camera.target.to_array())?)?;
        dict.set_item("up", PyTuple::new(py, camera.up.to_array())?)?;
        match camera.projection {
            lineao::Projection::Perspective { fov_y_deg } => dict.set_item("fov", fov_y_deg)?,
            lineao::Projection::Orthographic { height } => dict.set_item("ortho", height)?,
        }
        Ok(dict)
    }

    /// The adapter the session renders on, e.g. "llvmpipe (LLVM 19.1.7, 256 bits) (Vulkan, Cpu)".
    fn device(&self) -> String {
        self.session.gpu.describe()
    }

    /// Streamlines and vertices on the GPU.
    fn counts(&self) -> (usize, usize) {
        (self.session.lines.geometry.streamlines, self.session.lines.geometry.vertices)
    }
}

impl Renderer {
    /// A frame's arguments from `settings`, checked against what the session was opened with;
    /// the session's camera (when they name one) and sky follow them.
    fn frame_args(&mut self, settings: &Bound<'_, PyDict>) -> PyResult<RenderArgs> {
        let args = parse(settings, self.opened.file.as_ref())?;
        let same = |a: &RenderArgs| {
            let field = a.style.color.field();
            (
                a.style.surfaces.clone(),
                a.style.tube_radius_field.clone(),
                field,
                a.source.scene,
                a.source.vertices,
                a.source.seed,
                a.file.clone(),
            )
        };
        if same(&args) != same(&self.opened) {
            return Err(PyValueError::new_err(
                "surfaces, tube_radius_field, a colour field and the scene are set when the Renderer is made",
            ));
        }
        // A frame without a camera keeps the last one (Python passes whole cameras).
        if args.camera.eye.is_some()
            || args.camera.target.is_some()
            || args.camera.up.is_some()
            || args.camera.fov.is_some()
            || args.camera.ortho.is_some()
            || !args.figure.orbit.is_empty()
        {
            let hint = self.session.lines.hint;
            self.session.camera = lineao_session::render::camera(&args, &hint).map_err(render_error)?;
        }
        self.session.sky = lineao_session::render::sky(&args, self.session.camera.up);
        Ok(args)
    }
}

/// Writes `image` ((H, W, 4) uint8) as an sRGB PNG at `path`, or returns the PNG's bytes when
/// `path` is None.
#[pyfunction]
#[pyo3(name = "png", signature = (image, path=None))]
fn encode_png(
    py: Python<'_>,
    image: numpy::PyReadonlyArray3<'_, u8>,
    path: Option<PathBuf>,
) -> PyResult<Option<Vec<u8>>> {
    let shape = image.shape();
    if shape[2] != 4 {
        return Err(PyValueError::new_err(format!("image: expected shape (height, width, 4), got {shape:?}")));
    }
    let (h, w) = (shape[0] as u32, shape[1] as u32);
    let bytes: Vec<u8> = match image.as_slice() {
        Ok(bytes) => bytes.to_vec(),
        Err(_) => image.as_array().iter().copied().collect(),
    };
    py.detach(|| match path {
        Some(path) => lineao_session::output::write_png(&path, w, h, &bytes).map(|()| None),
        None => lineao_session::output::encode_png(w, h, &bytes).map(Some),
    })
    .map_err(|e| PyRuntimeError::new_err(format!("{e:#}")))
}

/// The eyes of a turntable of `frames` from a camera (eye, target, up), `degrees` in all:
/// `lineao render --turntable`'s cameras.
#[pyfunction]
fn turntable(eye: [f32; 3], target: [f32; 3], up: [f32; 3], frames: u32, degrees: f32) -> Vec<[f32; 3]> {
    let camera = lineao::Camera {
        eye: eye.into(),
        target: target.into(),
        up: up.into(),
        projection: lineao::Projection::Perspective { fov_y_deg: 30.0 },
    };
    lineao_session::cameras::turntable(&camera, frames, degrees).iter().map(|c| c.eye.to_array()).collect()
}

/// Writes `frames` ((H, W, 4) uint8 each, one size) as the movie `path` names at `fps`:
/// `lineao render --turntable`'s `--movie` (an animated PNG, or a file ffmpeg writes).
#[pyfunction]
fn write_movie(py: Python<'_>, frames: Vec<numpy::PyReadonlyArray3<'_, u8>>, path: PathBuf, fps: u32) -> PyResult<()> {
    let mut images = Vec::with_capacity(frames.len());
    for frame in &frames {
        let shape = frame.shape();
        if shape[2] != 4 {
            return Err(PyValueError::new_err(format!("frames: expected shape (height, width, 4), got {shape:?}")));
        }
        let data = match frame.as_slice() {
            Ok(bytes) => bytes.to_vec(),
            Err(_) => frame.as_array().iter().copied().collect(),
        };
        images.push(lineao_session::label::Rgba8 { width: shape[1] as u32, height: shape[0] as u32, data });
    }
    py.detach(|| lineao_session::figure::write_movie(&images, &path, fps))
        .map_err(|e| PyValueError::new_err(format!("{e:#}")))
}

#[pymodule]
fn _lineao(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("LoadError", m.py().get_type::<LoadError>())?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(sample_volume, m)?)?;
    m.add_function(wrap_pyfunction!(save, m)?)?;
    m.add_function(wrap_pyfunction!(select, m)?)?;
    m.add_function(wrap_pyfunction!(settings, m)?)?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(encode_png, m)?)?;
    m.add_function(wrap_pyfunction!(turntable, m)?)?;
    m.add_function(wrap_pyfunction!(write_movie, m)?)?;
    m.add_class::<Renderer>()?;
    Ok(())
}
