//! The page: eframe's web runner on WebGPU running the native viewer's [`App`] with its worker
//! on this thread ([`App::inline`]); files from a drop, the file input or `?url=`, handed to the
//! worker piece by piece as they are read ([`Source::Feed`]): a .tck, .tsf or .trk (gzip or
//! not) is decoded and drawn as it arrives, whatever its size — the GPU's memory is the limit —
//! while the formats read whole are refused by size before anything is allocated;
//! `window.lineaoStatus` and [`readback`] for tests. `web/index.html` loads it and says what to
//! do where WebGPU is missing.

use std::cell::RefCell;
use std::sync::{Arc, OnceLock};

use eframe::egui_wgpu::{WgpuSetup, WgpuSetupCreateNew};
use js_sys::{Array, Float32Array, Object, Promise, Reflect, Uint8Array};
use lineao::readback::TextureData;
use lineao_cli::args::ColorArg;
use lineao_cli::source::{Sampled, SharedFeed, Source};
use lineao_cli::view::App;
use lineao_cli::view::controls::colours_by_a_file;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::JsFuture;

use crate::check::Meta;
use crate::query::{self, LinkSource};

/// What arrives from outside the UI frame: files being read by futures, tests' requests.
enum Inbound {
    Progress {
        name: String,
        bytes: u64,
        total: Option<u64>,
    },
    /// A file whose pieces its reader pushes into `feed`.
    Open {
        name: String,
        feed: SharedFeed,
        from_url: bool,
    },
    Failed(String),
    /// What the page is doing before a dataset loads (fetching the file that colours it).
    Busy(String),
    /// A built-in scene to open (once the values that colour it have arrived).
    Scene(Source),
    /// A NIfTI volume read whole, to show as slices (or why it cannot be), by the name it came
    /// by (its address, or a dropped file's name); whether it came from the URL's `volume=` (a
    /// link can name it) or was dropped or picked (no link can).
    Anatomy {
        name: String,
        volume: Result<lineao_tracts::Volume, String>,
        from_url: bool,
    },
    /// A track scalar file (.tsf) or a volume read whole: the values the tractogram is coloured
    /// by (or why they cannot be).
    Values(Result<Sampled, String>),
    Readback {
        panel: usize,
        resolve: js_sys::Function,
        reject: js_sys::Function,
    },
}

thread_local! {
    static INBOX: RefCell<Vec<Inbound>> = const { RefCell::new(Vec::new()) };
    static CONTEXT: RefCell<Option<egui::Context>> = const { RefCell::new(None) };
    /// The most bytes of a file the page keeps to read it again (the URL's `hold`).
    static HOLD: std::cell::Cell<u64> = const { std::cell::Cell::new(crate::HOLD_BYTES) };
    /// Where the URL's `slices=` puts the slices of a volume opened.
    static SLICES: std::cell::Cell<Option<[Option<f32>; 3]>> = const { std::cell::Cell::new(None) };
}

/// Asks the UI for a frame (a piece of a file arrived).
fn repaint() {
    CONTEXT.with(|ctx| {
        if let Some(ctx) = &*ctx.borrow() {
            ctx.request_repaint();
        }
    });
}

fn post(message: Inbound) {
    INBOX.with(|inbox| inbox.borrow_mut().push(message));
    CONTEXT.with(|ctx| {
        if let Some(ctx) = &*ctx.borrow() {
            ctx.request_repaint();
        }
    });
}

/// A JavaScript error's message.
fn js_message(value: &JsValue) -> String {
    value
        .dyn_ref::<js_sys::Error>()
        .map(|e| String::from(e.message()))
        .or_else(|| value.as_string())
        .unwrap_or_else(|| format!("{value:?}"))
}

/// Starts the viewer in the canvas `canvas_id`, with the options of the page's URL.
/// `adapter` names the browser's adapter (its `GPUAdapterInfo`, which wgpu does not pass on).
#[wasm_bindgen]
pub async fn start(canvas_id: String, adapter: String) -> Result<(), JsValue> {
    let window = web_sys::window().ok_or("no window")?;
    let document = window.document().ok_or("no document")?;
    let canvas = document
        .get_element_by_id(&canvas_id)
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok())
        .ok_or_else(|| format!("no canvas '{canvas_id}'"))?;
    let page = query::parse(&window.location().search()?).map_err(|e| JsValue::from(js_sys::Error::new(&e)))?;
    let mut options = lineao_cli::view::options(&page.view);
    HOLD.with(|h| h.set(page.hold_bytes));
    SLICES.with(|s| s.set(page.view.slices));
    if let Some(url) = page.volume.clone() {
        wasm_bindgen_futures::spawn_local(async move {
            post(Inbound::Anatomy { volume: fetch_volume(&url).await, name: url, from_url: true });
        });
    }
    // A file by its address replaces the scene; a built-in scene waits for the values that
    // colour it (a volume is sampled at each chunk's points as they arrive: the viewer keeps
    // none to sample later).
    let scene = match (&page.url, &page.values) {
        (None, None) => None,
        (url, _) => options.source.take().filter(|_| url.is_none()),
    };
    if page.url.is_some() || page.values.is_some() {
        let (url, values) = (page.url.clone(), page.values.clone());
        wasm_bindgen_futures::spawn_local(async move {
            // The values first: the tractogram takes them as it arrives (a volume is sampled at
            // each chunk's points, which the page need not keep).
            let values = match &values {
                Some(color) => fetch_values(color).await,
                None => Ok(None),
            };
            let error = match values {
                Ok(values) => {
                    if let Some(values) = values {
                        post(Inbound::Values(Ok(values)));
                    }
                    None
                }
                Err(message) => Some(message),
            };
            if let Some(scene) = scene {
                post(Inbound::Scene(scene));
            }
            let opened = match url {
                Some(url) => match open_url(&url).await {
                    Ok((body, feed)) => Some((url, body, feed)),
                    Err(e) => return post(Inbound::Failed(e)),
                },
                None => None,
            };
            // Said once the tractogram's load has begun (a load clears the error shown
            // before); the tractogram goes on in its own colours.
            if let Some(message) = error {
                post(Inbound::Values(Err(message)));
            }
            if let Some((url, body, feed)) = opened {
                read_stream(&url, body, &feed).await;
            }
        });
    }
    let mut setup = WgpuSetupCreateNew::without_display_handle();
    // WebGPU only: lineao's passes are compute shaders and storage textures, which WebGL lacks.
    setup.instance_descriptor.backends = wgpu::Backends::BROWSER_WEBGPU;
    setup.device_descriptor = Arc::new(lineao::Gpu::device_descriptor);
    let mut web_options = eframe::WebOptions::default();
    web_options.wgpu_options.wgpu_setup = WgpuSetup::CreateNew(setup);
    let source = match (&page.url, page.view.scene) {
        (Some(url), _) => LinkSource::Url(url.clone()),
        (None, scene) => LinkSource::Scene(scene.unwrap_or(lineao_tracts::SceneKind::Bundles).name().into()),
    };
    let runner = eframe::WebRunner::new();
    runner
        .start(
            canvas,
            web_options,
            Box::new(move |cc| {
                let state = cc.wgpu_render_state.clone().ok_or("eframe made no wgpu renderer")?;
                lineao::check_adapter(&state.adapter)?;
                let info = state.adapter.get_info();
                let name = if adapter.is_empty() { info.name.clone() } else { adapter };
                let adapter = format!("{name} ({:?})", info.backend);
                let gpu = lineao::Gpu::new(
                    state.instance.clone(),
                    state.adapter.clone(),
                    state.device.clone(),
                    state.queue.clone(),
                );
                let mut app = App::inline(gpu, state, options);
                app.open_file = Some(Box::new(pick_file));
                CONTEXT.with(|c| *c.borrow_mut() = Some(cc.egui_ctx.clone()));
                Ok(Box::new(Page {
                    app,
                    source,
                    volume: page.volume,
                    values: page.values.and_then(|color| color.field()),
                    adapter,
                    requests: Vec::new(),
                    readbacks: Vec::new(),
                    status: String::new(),
                    link: None,
                }))
            }),
        )
        .await?;
    // The runner lives as long as the page.
    std::mem::forget(runner);
    Ok(())
}

/// Opens `file` (dropped on the page or picked in its file input): a NIfTI volume is the
/// anatomy, shown as slices with the tractogram; a track scalar file (.tsf) the values the
/// tractogram is coloured by (read whole, so it arrives after a tractogram dropped with it
/// has begun to); anything else is a dataset.
#[wasm_bindgen]
pub fn open_file(file: web_sys::File) {
    let (name, size) = (file.name(), file.size() as u64);
    if let Some(message) = crate::too_large(&name, size) {
        return post(Inbound::Failed(message));
    }
    let nifti = lineao_tracts::Volume::is_nifti_name(&name);
    if nifti || lineao_cli::view::app::is_tsf(std::path::Path::new(&name)) {
        // Read whole: a .tsf too, though a tractogram of its format would be streamed.
        if let Some(message) = crate::too_large_whole(&name, size) {
            return post(Inbound::Values(Err(format!("{message}; the lines keep their colours"))));
        }
        return wasm_bindgen_futures::spawn_local(async move {
            let bytes = JsFuture::from(file.array_buffer()).await;
            let bytes = bytes.map(|b| Uint8Array::new(&b).to_vec()).map_err(|e| format!("{name}: {}", js_message(&e)));
            post(match nifti {
                true => {
                    Inbound::Anatomy { volume: bytes.and_then(|b| crate::volume(&name, &b)), name, from_url: false }
                }
                false => Inbound::Values(
                    bytes.and_then(|b| Sampled::tsf_from_bytes(&name, &b).map_err(|e| format!("{e:#}"))),
                ),
            });
        });
    }
    let feed = SharedFeed::new(Some(size), HOLD.with(|h| h.get()));
    post(Inbound::Open { name: name.clone(), feed: feed.clone(), from_url: false });
    wasm_bindgen_futures::spawn_local(async move {
        read_stream(&name, file.stream(), &feed).await;
    });
}

/// Reads back panel `panel`'s last frame: `{ meta (JSON text), nd: [Float32Array per level],
/// zoom, ao }` — see [`crate::check`].
#[wasm_bindgen]
pub fn readback(panel: usize) -> Promise {
    Promise::new(&mut |resolve, reject| post(Inbound::Readback { panel, resolve, reject }))
}

/// File ▸ Open…: the page's file input.
fn pick_file() {
    let input = web_sys::window().and_then(|w| w.document()).and_then(|d| d.get_element_by_id("lineao-file"));
    if let Some(input) = input.and_then(|e| e.dyn_into::<web_sys::HtmlElement>().ok()) {
        input.click();
    }
}

/// The response to a GET of `url` (relative to the page) and its stated size: an error for a
/// failed request, an HTTP error status, or a size over what the page reads of the format.
async fn get(url: &str) -> Result<(web_sys::Response, Option<u64>), String> {
    let window = web_sys::window().ok_or("no window")?;
    let response = JsFuture::from(window.fetch_with_str(url))
        .await
        .map_err(|e| format!("{url}: cannot fetch: {}", js_message(&e)))?;
    let response: web_sys::Response = response.dyn_into().map_err(|_| format!("{url}: not a response"))?;
    if !response.ok() {
        return Err(format!("{url}: HTTP {} {}", response.status(), response.status_text()));
    }
    let total = response.headers().get("content-length").ok().flatten().and_then(|v| v.parse::<u64>().ok());
    if let Some(message) = total.and_then(|t| crate::too_large(url, t)) {
        return Err(message);
    }
    Ok((response, total))
}

/// Fetches the file at `url` (relative to the page), whole, refused past what the page holds
/// of a file; with `progress`, the status bar says how much has arrived (a file the page waits
/// for before the tractogram: the values that colour it as it arrives).
async fn fetch_whole(url: &str, progress: bool) -> Result<Vec<u8>, String> {
    if progress {
        post(Inbound::Busy(format!("fetching {url} …")));
    }
    let (response, total) = get(url).await?;
    if let Some(message) = total.and_then(|t| crate::too_large_whole(url, t)) {
        return Err(message);
    }
    let mib = |b: u64| b as f64 / f64::from(1 << 20);
    let of = total.map_or(String::new(), |t| format!(" of {:.1}", mib(t)));
    let said = |bytes: usize| {
        if progress {
            post(Inbound::Busy(format!("fetching {url}: {:.1}{of} MiB", mib(bytes as u64))));
        }
    };
    let cannot = |e: JsValue| format!("{url}: cannot read: {}", js_message(&e));
    let body = response.body().ok_or_else(|| format!("{url}: the response has no body"))?;
    let reader: web_sys::ReadableStreamDefaultReader = body.get_reader().unchecked_into();
    // Room for its stated size up to 64 MiB (a header may lie; past that the vector grows as
    // the bytes arrive).
    let mut bytes = Vec::with_capacity(total.unwrap_or(0).min(64 << 20) as usize);
    loop {
        let chunk = JsFuture::from(reader.read()).await.map_err(cannot)?;
        if Reflect::get(&chunk, &"done".into()).ok().and_then(|d| d.as_bool()).unwrap_or(true) {
            return Ok(bytes);
        }
        let value: Uint8Array = Reflect::get(&chunk, &"value".into()).map_err(cannot)?.unchecked_into();
        if let Some(message) = crate::too_large_whole(url, (bytes.len() + value.length() as usize) as u64) {
            let _ = reader.cancel();
            return Err(message);
        }
        let start = bytes.len();
        bytes.resize(start + value.length() as usize, 0);
        value.copy_to(&mut bytes[start..]);
        said(bytes.len());
    }
}

/// Fetches the NIfTI volume at `url` (relative to the page), whole.
async fn fetch_volume(url: &str) -> Result<lineao_tracts::Volume, String> {
    crate::volume(url, &fetch_whole(url, false).await?)
}

/// Fetches the file of `color=volume:ADDRESS` or `color=tsf:ADDRESS`: the values the lines are
/// coloured by (`None` for another colour).
async fn fetch_values(color: &ColorArg) -> Result<Option<Sampled>, String> {
    let Some(url) = color.values_file().map(|path| path.to_string_lossy().into_owned()) else { return Ok(None) };
    let bytes = fetch_whole(&url, true).await.map_err(|e| format!("{e}; the lines keep their colours"))?;
    let sampled = match color {
        ColorArg::Volume(_) => crate::volume(&url, &bytes).map(|volume| Sampled::from_volume(&url, volume)),
        _ => Sampled::tsf_from_bytes(&url, &bytes).map_err(|e| format!("{e:#}")),
    };
    sampled.map(Some).map_err(|e| format!("{e}; the lines keep their colours"))
}

/// Starts fetching `url` (relative to the page) into a feed the viewer opens as it arrives:
/// the response's body, which [`read_stream`] reads into the feed.
async fn open_url(url: &str) -> Result<(web_sys::ReadableStream, SharedFeed), String> {
    post(Inbound::Progress { name: url.to_string(), bytes: 0, total: None });
    let (response, total) = get(url).await?;
    let body = response.body().ok_or_else(|| format!("{url}: the response has no body"))?;
    let feed = SharedFeed::new(total, HOLD.with(|h| h.get()));
    post(Inbound::Open { name: url.to_string(), feed: feed.clone(), from_url: true });
    Ok((body, feed))
}

/// Reads `stream` to its end into `feed`, a piece at a time as the browser hands them over,
/// never more than [`READ_AHEAD_BYTES`] ahead of the decoder (a file arrives faster than it is
/// decoded, and the page's memory is not to hold it); a format read whole is refused past
/// [`crate::MAX_FILE_BYTES`].
async fn read_stream(name: &str, stream: web_sys::ReadableStream, feed: &SharedFeed) {
    let reader: web_sys::ReadableStreamDefaultReader = stream.get_reader().unchecked_into();
    let mut read = 0u64;
    loop {
        while feed.ahead() > READ_AHEAD_BYTES && !feed.abandoned() {
            pause(20).await;
        }
        if feed.abandoned() {
            // Its load ended (an error, another file opened): nobody reads on.
            let _ = reader.cancel();
            return;
        }
        let chunk = match JsFuture::from(reader.read()).await {
            Ok(chunk) => chunk,
            Err(e) => return feed.lock().fail(format!("{name}: cannot read: {}", js_message(&e))),
        };
        if Reflect::get(&chunk, &"done".into()).ok().and_then(|d| d.as_bool()).unwrap_or(true) {
            break;
        }
        let value: Uint8Array = match Reflect::get(&chunk, &"value".into()) {
            Ok(value) => value.unchecked_into(),
            Err(e) => return feed.lock().fail(js_message(&e)),
        };
        read += value.length() as u64;
        if let Some(message) = crate::too_large(name, read) {
            let _ = reader.cancel();
            return feed.lock().fail(message);
        }
        feed.lock().push(value.to_vec());
        repaint();
    }
    feed.lock().end();
    repaint();
}

/// How far the page reads a file ahead of its decoder.
const READ_AHEAD_BYTES: u64 = 64 << 20;

/// Resolves after `ms` milliseconds (the page's event loop runs meanwhile).
async fn pause(ms: i32) {
    let promise = Promise::new(&mut |resolve, _| {
        if let Some(window) = web_sys::window() {
            let _ = window.set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, ms);
        }
    });
    let _ = JsFuture::from(promise).await;
}

/// A texture being copied back: its buffer and layout, and whether the mapping finished.
struct Copy {
    buffer: wgpu::Buffer,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    padded_row: u32,
    mapped: Arc<OnceLock<bool>>,
}

struct PendingReadback {
    meta: Meta,
    /// ND levels, then the zoom map, then the AO.
    copies: Vec<Copy>,
    resolve: js_sys::Function,
    reject: js_sys::Function,
}

struct Page {
    app: App,
    source: LinkSource,
    /// The URL's `volume=`, which the link keeps while its volume is shown.
    volume: Option<String>,
    /// The field of the URL's `color=volume:ADDRESS` or `tsf:ADDRESS` (named so), which the
    /// link keeps while the lines are coloured by it; no link names a file dropped.
    values: Option<String>,
    adapter: String,
    /// Readbacks asked for, and those copying.
    requests: Vec<(usize, js_sys::Function, js_sys::Function)>,
    readbacks: Vec<PendingReadback>,
    /// The last JSON published as `window.lineaoStatus`, and the last link put in the URL.
    status: String,
    link: Option<String>,
}

impl eframe::App for Page {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        for message in INBOX.with(|inbox| std::mem::take(&mut *inbox.borrow_mut())) {
            match message {
                Inbound::Progress { name, bytes, total } => self.app.show_loading(&name, bytes, total),
                Inbound::Open { name, feed, from_url } => {
                    self.source = if from_url { LinkSource::Url(name.clone()) } else { LinkSource::None };
                    self.app.load(Source::Feed { name, feed });
                }
                Inbound::Failed(message) => self.app.fail(message),
                Inbound::Busy(what) => self.app.show_busy(what),
                Inbound::Scene(source) => self.app.load(source),
                Inbound::Anatomy { volume: Ok(volume), name, from_url } => {
                    if !from_url {
                        self.volume = None;
                    }
                    self.app.set_anatomy(&name, Arc::new(volume), SLICES.with(|s| s.get()));
                }
                Inbound::Anatomy { volume: Err(message), .. } => {
                    self.app.error = Some(format!("{message}; the tractogram is shown without slices"));
                }
                Inbound::Values(Ok(values)) => self.app.colour_by(Arc::new(values)),
                Inbound::Values(Err(message)) => self.app.error = Some(message),
                Inbound::Readback { panel, resolve, reject } => self.requests.push((panel, resolve, reject)),
            }
        }
        self.app.show(ui);
        // Readbacks start between the worker's steps (a step holds the worker).
        if !self.requests.is_empty() {
            if self.app.worker().is_some() {
                for (panel, resolve, reject) in std::mem::take(&mut self.requests) {
                    if let Err(e) = self.start_readback(panel, resolve, &reject) {
                        let _ = reject.call1(&JsValue::NULL, &js_sys::Error::new(&e));
                    }
                }
            } else {
                ctx.request_repaint();
            }
        }
        self.finish_readbacks(&ctx);
        self.publish_status();
        self.publish_link();
    }
}

impl Page {
    /// Copies panel `panel`'s ND pyramid, zoom map and raw AO into mappable buffers.
    fn start_readback(
        &mut self,
        panel: usize,
        resolve: js_sys::Function,
        reject: &js_sys::Function,
    ) -> Result<(), String> {
        let worker = self.app.worker().ok_or("the worker is busy")?;
        let chain = worker.chain(panel).ok_or_else(|| format!("panel {panel} has rendered nothing"))?;
        let (targets, view) = chain.targets().zip(chain.frame_view()).ok_or("nothing was rendered")?;
        let settings = chain.settings().clone();
        let raw = chain.stage().and_then(|s| s.unblurred()).unwrap_or(&targets.ao);
        let textures: Vec<&wgpu::Texture> =
            targets.nd.iter().map(|t| &t.texture).chain([&targets.zoom.texture, &raw.texture]).collect();
        let (device, queue) = (&worker.gpu().device, &worker.gpu().queue);
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("lineao::web::readback") });
        let mut copies = Vec::new();
        for texture in textures {
            let (w, h, format) = (texture.width(), texture.height(), texture.format());
            let texel = format.block_copy_size(None).ok_or("a texture without a copy size")?;
            let padded_row = (w * texel).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lineao::web::readback"),
                size: u64::from(padded_row) * u64::from(h),
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            encoder.copy_texture_to_buffer(
                texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(padded_row),
                        rows_per_image: Some(h),
                    },
                },
                texture.size(),
            );
            copies.push(Copy { buffer, size: (w, h), format, padded_row, mapped: Arc::default() });
        }
        queue.submit([encoder.finish()]);
        for copy in &copies {
            let mapped = copy.mapped.clone();
            copy.buffer.slice(..).map_async(wgpu::MapMode::Read, move |result| {
                let _ = mapped.set(result.is_ok());
            });
        }
        let levels = targets.nd.iter().map(|t| [t.texture.width(), t.texture.height()]).collect();
        let meta = Meta { settings, view: *view, levels, adapter: self.adapter.clone() };
        self.readbacks.push(PendingReadback { meta, copies, resolve, reject: reject.clone() });
        Ok(())
    }

    /// Resolves the readbacks whose buffers are mapped.
    fn finish_readbacks(&mut self, ctx: &egui::Context) {
        let (done, waiting): (Vec<_>, Vec<_>) = std::mem::take(&mut self.readbacks)
            .into_iter()
            .partition(|r| r.copies.iter().all(|c| c.mapped.get().is_some()));
        self.readbacks = waiting;
        if !self.readbacks.is_empty() {
            ctx.request_repaint();
        }
        for readback in done {
            match readback_value(&readback) {
                Ok(value) => {
                    let _ = readback.resolve.call1(&JsValue::NULL, &value);
                }
                Err(e) => {
                    let _ = readback.reject.call1(&JsValue::NULL, &js_sys::Error::new(&e));
                }
            }
        }
    }

    /// `window.lineaoStatus`: what the page shows, for tests and for scripts around it.
    fn publish_status(&mut self) {
        let app = &self.app;
        let state = match (app.error(), app.is_loading() || !app.settled() || app.shown.is_none()) {
            (Some(_), _) => "error",
            (None, true) => "loading",
            (None, false) => "ready",
        };
        let frame = app.shown.as_ref();
        let methods: Vec<&str> =
            frame.map(|f| f.view.panels.iter().map(|p| p.settings.method.name()).collect()).unwrap_or_default();
        let gpu_ms: Vec<Option<f64>> = frame
            .map(|f| f.times.iter().map(|t| t.as_ref().map(|t| t.iter().map(|p| p.ms).sum())).collect())
            .unwrap_or_default();
        let passes: Vec<Vec<(String, f64)>> = frame
            .map(|f| f.times.iter().map(|t| t.iter().flatten().map(|p| (p.name.to_string(), p.ms)).collect()).collect())
            .unwrap_or_default();
        let message = match (app.error(), state) {
            (Some(e), _) => e.to_string(),
            (None, "ready") => "ready".into(),
            _ => app.busy().unwrap_or("loading").into(),
        };
        let status = serde_json::json!({
            "state": state,
            "message": message,
            "name": app.dataset.as_ref().map(|d| d.name.clone()),
            "streamlines": app.dataset.as_ref().map(|d| d.streamlines),
            "vertices": app.dataset.as_ref().map(|d| d.vertices),
            "loadMs": app.dataset.as_ref().map(|d| d.load_ms),
            "firstMs": app.dataset.as_ref().map(|d| d.first_ms),
            "firstPictureMs": app.first_frame_ms,
            "complete": app.dataset.as_ref().map(|d| d.complete),
            "bytesRead": app.progress().map(|p| p.0),
            "readable": app.dataset.as_ref().map(|d| d.readable),
            "method": methods.join(" | "),
            "methods": methods,
            "adapter": self.adapter,
            "size": frame.map(|f| [f.size.0, f.size.1]),
            "gpuMs": gpu_ms,
            "passes": passes,
            "frames": app.frames_received,
            "anatomy": app.anatomy().map(|v| v.dims),
            "slices": frame.and_then(|f| f.view.panels[0].settings.slices.as_ref().map(|s| s.positions)),
            // The per-vertex fields the lines can be coloured by, and the range of the one they are.
            "fields": app.dataset.as_ref().map(|d| d.fields.iter().map(|(name, _)| name.clone()).collect::<Vec<_>>()),
            "colorRange": frame.and_then(|f| match f.view.panels[0].settings.line_color {
                lineao::LineColor::Scalar { range, .. } => Some(range),
                _ => None,
            }),
            "raysPerPixel": frame.map(|f| f.rays.iter().map(|r| r.map(|r| r.progress.rays_per_pixel)).collect::<Vec<_>>()),
        })
        .to_string();
        if status != self.status {
            if let (Some(window), Ok(value)) = (web_sys::window(), js_sys::JSON::parse(&status)) {
                let _ = Reflect::set(&window, &"lineaoStatus".into(), &value);
            }
            self.status = status;
        }
    }

    /// Keeps the page's URL the link of what it shows (methods, preset, camera), once it rests.
    fn publish_link(&mut self) {
        let app = &self.app;
        if !app.settled() || app.error().is_some() {
            return;
        }
        let Some(frame) = &app.shown else { return };
        if let Some(dataset) = &app.dataset
            && let Ok(kind) = dataset.name.parse::<lineao_tracts::SceneKind>()
        {
            self.source = LinkSource::Scene(kind.name().into());
        }
        let methods: Vec<&str> = frame.view.panels.iter().map(|p| p.settings.method.name()).collect();
        let orbit = app.camera.as_ref().map(|c| c.orbit_values());
        let ortho = app.camera.as_ref().is_some_and(|c| c.orthographic);
        let mut flags = app.controls.link_flags();
        // The colour of a file's values: an address only where the URL fetched it (its `color=`,
        // or its `volume=` coloured by from the side panel).
        let anatomy = self.volume.as_ref().map(|url| format!("volume:{url}"));
        let named = |value: &String| self.values.as_ref() == Some(value) || anatomy.as_ref() == Some(value);
        flags.retain(|(flag, value)| flag != "color" || !colours_by_a_file(value) || named(value));
        let link =
            query::link((&self.source, self.volume.as_deref()), &methods, app.controls.preset, (orbit, ortho), &flags);
        if self.link.as_ref() != Some(&link) {
            if let Some(history) = web_sys::window().and_then(|w| w.history().ok()) {
                let _ = history.replace_state_with_url(&JsValue::NULL, "", Some(&link));
            }
            self.link = Some(link);
        }
    }
}

/// The JavaScript value of a finished readback.
fn readback_value(readback: &PendingReadback) -> Result<JsValue, String> {
    let mut images = Vec::new();
    for copy in &readback.copies {
        if copy.mapped.get() != Some(&true) {
            return Err("a readback buffer could not be mapped".into());
        }
        let (w, h) = copy.size;
        let texel = copy.format.block_copy_size(None).unwrap_or(4);
        let mut bytes = Vec::with_capacity((w * h * texel) as usize);
        {
            let mapped = copy.buffer.slice(..).get_mapped_range().map_err(|e| format!("a readback buffer: {e}"))?;
            for row in mapped.chunks(copy.padded_row as usize).take(h as usize) {
                bytes.extend_from_slice(&row[..(w * texel) as usize]);
            }
        }
        copy.buffer.unmap();
        images.push(TextureData { width: w, height: h, format: copy.format, bytes });
    }
    let (ao, rest) = images.split_last().ok_or("no images")?;
    let (zoom, nd) = rest.split_last().ok_or("no zoom map")?;
    let floats = |values: &[f32]| Float32Array::from(values);
    let levels = Array::new();
    for level in nd {
        let texels: Vec<f32> = level.to_vec4().into_iter().flatten().collect();
        levels.push(&floats(&texels));
    }
    let value = Object::new();
    let meta = serde_json::to_string(&readback.meta).map_err(|e| e.to_string())?;
    let set = |key: &str, v: &JsValue| Reflect::set(&value, &key.into(), v).map(|_| ()).map_err(|e| js_message(&e));
    set("meta", &meta.into())?;
    set("nd", &levels)?;
    set("zoom", &floats(&zoom.to_f32()))?;
    set("ao", &floats(&ao.to_f32()))?;
    Ok(value.into())
}
