//! What a method is to the chain and the front ends: its [`MethodInfo`] (names, spans, shaders,
//! its [`Stage`] and its own settings, [`Own`]), the stage's trait and the bench's passes. Each
//! method's folder ends in one `METHOD: MethodInfo`; the registry (`registry.rs`) lists them.

use crate::Error;
use crate::camera::FrameView;
use crate::method::AoMethod;
use crate::method::setting::{About, Context, Setting, Value};
use crate::preset::Preset;
use crate::settings::ChainSettings;
use crate::targets::{FrameTargets, Target};
use crate::timing::Span;

/// A method's CPU reference of its frame ([`MethodInfo`]'s `reference`).
#[cfg(feature = "reference")]
pub(crate) type CpuReference = fn(&crate::verify::FrameInputs) -> Result<crate::verify::ReferenceAo, Error>;

/// How a method builds its stage for a device and settings.
pub(crate) type BuildStage = fn(&wgpu::Device, &ChainSettings) -> Box<dyn Stage>;

/// Everything the library and the front ends know of a method.
pub struct MethodInfo {
    /// The name on the command line, in `params.json`, in Python and in docs/reference.md.
    pub name: &'static str,
    /// What a method list in a user interface shows.
    pub label: &'static str,
    /// One line of help: what the method is and where it comes from.
    pub help: &'static str,
    /// Whether the method is screen-space AO in the chain, shown by `--grid` and the viewer's
    /// list among the others (the ray-traced truth, progressive and scene-bound, is not).
    pub screen_space: bool,
    /// Whether it traces rays through the scene (the ray-traced truth): it needs the scene's
    /// BVH ([`crate::AoChain::set_ray_scene`]), accumulates its picture over frames, and its
    /// rays start on lines drawn at full detail. The CPU truth (`--cpu`) can stand in.
    pub traces_scene: bool,
    /// What it estimates: which ray-traced truth `lineao score` holds its picture to.
    pub estimates: Estimate,
    /// The timing spans its stage can record, in chain order (docs/reference.md's names).
    pub spans: &'static [&'static str],
    /// Its WGSL files, by the name its passes compose them under, and the numbers its WGSL
    /// shares with its CPU reference, which Rust writes into the WGSL
    /// ([`crate::shader::CONSTANTS`]).
    pub(crate) library: crate::shader::Library,
    /// Its stage; `None` for a method that runs no pass (`none`).
    pub(crate) build: Option<BuildStage>,
    /// Whether what its stage allocates for a guard-banded frame of this size fits the device's
    /// limits (an [`crate::Error::TooLarge`] saying what does not), checked before a frame of
    /// that size is made. The targets a method alone reads and writes are its stage's own,
    /// allocated in [`Stage::resize`].
    pub(crate) fits: fn((u32, u32), &wgpu::Limits) -> Result<(), crate::Error>,
    /// Its own settings: their descriptions, from which the front ends make their flags,
    /// keywords, controls and URL keys, their values in each preset, their validation and what
    /// they need of the ND pyramid ([`Own`], or [`NO_SETTINGS`]).
    pub(crate) own: &'static dyn OwnSettings,
    /// What `lineao bench` times of it, by docs/reference.md's names.
    pub bench: &'static [BenchPass],
    /// Its other form that `score`, the fit and `--grid` show as a method of their own.
    pub variant: Option<Variant>,
    /// What `lineao score --fit` searches of it for lines `line_width_px` wide, of its main
    /// form or (`variant`) its variant: the first candidate the paper's (our defaults');
    /// `None`: the fit leaves it out.
    pub fit: Option<fn(line_width_px: f32, variant: bool) -> Vec<FitCandidate>>,
    /// Its stage's occlusion on the CPU from the frame's read-back inputs
    /// ([`crate::verify::reference_ao`]); `None` where its frame has no reference of its own.
    #[cfg(feature = "reference")]
    pub(crate) reference: Option<CpuReference>,
}

/// A method's other form, made by a value of one of its settings, that `lineao score`, the fit
/// and `--grid` show beside it as a method of their own (LineAO's `reference`: the authors'
/// shader beside the paper's equations).
#[derive(Debug, PartialEq, Eq)]
pub struct Variant {
    /// The setting's flag (`variant`).
    pub setting: &'static str,
    /// Its value for this form (`reference`); a panel's label adds it in brackets.
    pub value: &'static str,
    /// Its value for the method's main form (`paper`).
    pub main: &'static str,
    /// Its name as a method of its own (`lineao-reference`).
    pub name: &'static str,
    /// What the viewer's label adds (`authors' code`).
    pub label: &'static str,
    /// Its line of `--help`.
    pub help: &'static str,
}

/// A candidate of `lineao score --fit`: what its report calls it, and what it changes of the
/// paper's settings.
pub struct FitCandidate {
    /// Its label in the fit's report.
    pub label: String,
    /// What it changes.
    pub apply: Box<dyn Fn(&mut ChainSettings)>,
}

impl FitCandidate {
    /// The candidates that set a radius (`set`): the paper's, then `others`.
    pub(crate) fn radii(paper: f32, others: &[f32], set: fn(&mut ChainSettings, f32)) -> Vec<FitCandidate> {
        let radius = move |r: f32| FitCandidate { label: format!("radius {r}"), apply: Box::new(move |s| set(s, r)) };
        std::iter::once(paper).chain(others.iter().copied()).map(radius).collect()
    }
}

/// What a method estimates, so the ray-traced truth it is held to (`lineao score`, the fit).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimate {
    /// Ambient occlusion: the share of the hemisphere's rays that hit within the reach.
    Occlusion,
    /// Volumetric Obscurance (Loos & Sloan 2010): the share of a ball (a half ball where VO
    /// clamps to the normal) filled with geometry.
    Obscurance,
}

/// A pass of `lineao bench` that times a method: its stage, built and prepared with the bench's
/// settings as [`BenchPass::settings`] changes them, on the bench's G-buffer.
pub struct BenchPass {
    /// The pass's name in `lineao bench` (docs/reference.md's).
    pub name: &'static str,
    /// Changes the bench's settings (the papers', LineAO's preset, and this method) for frame
    /// `frame` of the run: a sample count, a variant, a new seed each frame for a new picture.
    pub settings: fn(&mut ChainSettings, u32),
    /// Of the stage's spans, those timed as one, from the first's start to the last's end; the
    /// stage's others run untimed in the same submission (so without timestamp queries, where
    /// the bench times the submission, the pass reports its whole stage).
    pub spans: &'static [&'static str],
    /// Its stage when not the method's (`lineao-tap-floor`: LineAO's shader that only sums its
    /// taps).
    pub(crate) build: Option<BuildStage>,
}

impl BenchPass {
    /// A pass of the method's own stage.
    pub(crate) const fn of(
        name: &'static str,
        spans: &'static [&'static str],
        settings: fn(&mut ChainSettings, u32),
    ) -> BenchPass {
        BenchPass { name, settings, spans, build: None }
    }

    /// The bench's settings for this pass of `method` in frame `frame`.
    pub fn settings_for(&self, method: AoMethod, bench: &ChainSettings, frame: u32) -> ChainSettings {
        let mut settings = ChainSettings { method, ..bench.clone() };
        (self.settings)(&mut settings, frame);
        settings
    }
}

/// A method's own settings `S` and what it does with them, found in a chain's settings at the
/// field its registry line names (`of`, `of_mut`): the one place a method's settings meet the
/// chain's. Its functions see `S` and a [`Context`], never the other methods' settings.
pub struct Own<S: 'static> {
    /// The descriptions of its settings, in the order front ends list them.
    pub(crate) settings: &'static [Setting<S>],
    /// Its settings in a chain's.
    pub(crate) of: fn(&ChainSettings) -> &S,
    /// Its settings in a chain's, to change.
    pub(crate) of_mut: fn(&mut ChainSettings) -> &mut S,
    /// Sets `preset`'s values of its own settings; the strength it is shown with.
    pub(crate) preset: fn(Preset, &mut S, &Context) -> f32,
    /// Checks how its values depend on each other (each value's range is its description's),
    /// an [`Error::OutOfRange`] naming the one out of range, or an [`Error::Conflict`].
    pub(crate) validate: fn(&S, &Context) -> Result<(), Error>,
    /// The levels of the G-buffer's ND pyramid its stage reads under them (1: the
    /// full-resolution maps alone).
    pub(crate) levels: fn(&S) -> u32,
    /// What a panel calls after one of its controls moved a value: the others changed so that
    /// the settings stay valid (SSAO's sphere kernel takes only its sample counts). The command
    /// line calls nothing: what it is given is checked, not changed.
    pub(crate) conform: fn(&mut S),
}

impl<S> Own<S> {
    /// Settings `settings` at the chain's field `of`, `of_mut`, which only the preset changes
    /// (`preset`), always valid, read at the full resolution alone: what a method fills in
    /// beyond.
    pub(crate) const fn at(
        settings: &'static [Setting<S>],
        of: fn(&ChainSettings) -> &S,
        of_mut: fn(&mut ChainSettings) -> &mut S,
        preset: fn(Preset, &mut S, &Context) -> f32,
    ) -> Own<S> {
        Own { settings, of, of_mut, preset, validate: |_, _| Ok(()), levels: |_| 1, conform: |_| {} }
    }
}

/// What the chain and the front ends do with any method's [`Own`] settings, in a chain's
/// settings; setting `index` is its description's place in the list.
pub(crate) trait OwnSettings: Sync {
    /// How many settings it describes.
    fn len(&self) -> usize;
    /// The description of setting `index`.
    fn about(&self, index: usize) -> &'static About;
    /// Whether setting `index` means anything under `chain`.
    fn applies(&self, index: usize, chain: &ChainSettings) -> bool;
    /// Setting `index`'s value in `chain`.
    fn get(&self, index: usize, chain: &ChainSettings) -> Value;
    /// Puts `value` into setting `index` of `chain`.
    fn set(&self, index: usize, chain: &mut ChainSettings, value: Value);
    /// Sets `preset`'s values and the strength.
    fn preset(&self, preset: Preset, chain: &mut ChainSettings);
    /// Checks every value: its range, then how they depend on each other.
    fn validate(&self, chain: &ChainSettings) -> Result<(), Error>;
    /// The pyramid levels its stage reads.
    fn levels(&self, chain: &ChainSettings) -> u32;
    /// Leaves its values valid after a panel's control moved one.
    fn conform(&self, chain: &mut ChainSettings);
}

impl<S: 'static> OwnSettings for Own<S> {
    fn len(&self) -> usize {
        self.settings.len()
    }

    fn about(&self, index: usize) -> &'static About {
        &self.settings[index].about
    }

    fn applies(&self, index: usize, chain: &ChainSettings) -> bool {
        (self.settings[index].applies)((self.of)(chain))
    }

    fn get(&self, index: usize, chain: &ChainSettings) -> Value {
        (self.settings[index].get)((self.of)(chain), &chain.context())
    }

    fn set(&self, index: usize, chain: &mut ChainSettings, value: Value) {
        (self.settings[index].set)((self.of_mut)(chain), value)
    }

    fn preset(&self, preset: Preset, chain: &mut ChainSettings) {
        let context = chain.context();
        chain.strength = (self.preset)(preset, (self.of_mut)(chain), &context);
    }

    fn validate(&self, chain: &ChainSettings) -> Result<(), Error> {
        let (own, context) = ((self.of)(chain), chain.context());
        for setting in self.settings {
            setting.about.check((setting.get)(own, &context))?;
        }
        (self.validate)(own, &context)
    }

    fn levels(&self, chain: &ChainSettings) -> u32 {
        (self.levels)((self.of)(chain))
    }

    fn conform(&self, chain: &mut ChainSettings) {
        (self.conform)((self.of_mut)(chain))
    }
}

/// The settings of a method that has none of its own: shown at strength 1 in every preset.
pub(crate) const NO_SETTINGS: &dyn OwnSettings = &NoSettings;

struct NoSettings;

impl OwnSettings for NoSettings {
    fn len(&self) -> usize {
        0
    }

    fn about(&self, index: usize) -> &'static About {
        unreachable!("a method without settings has no setting {index}")
    }

    fn applies(&self, _: usize, _: &ChainSettings) -> bool {
        false
    }

    fn get(&self, index: usize, _: &ChainSettings) -> Value {
        unreachable!("a method without settings has no setting {index}")
    }

    fn set(&self, _: usize, _: &mut ChainSettings, _: Value) {}

    fn preset(&self, _: Preset, chain: &mut ChainSettings) {
        chain.strength = 1.0;
    }

    fn validate(&self, _: &ChainSettings) -> Result<(), Error> {
        Ok(())
    }

    fn levels(&self, _: &ChainSettings) -> u32 {
        1
    }

    fn conform(&self, _: &mut ChainSettings) {}
}

/// One of a method's settings in a chain's ([`MethodInfo::settings`]): its description
/// ([`About`], which it derefs to) and its value read and written in a [`ChainSettings`].
#[derive(Clone, Copy)]
pub struct ChainSetting {
    own: &'static dyn OwnSettings,
    index: usize,
}

impl std::ops::Deref for ChainSetting {
    type Target = About;

    fn deref(&self) -> &About {
        self.own.about(self.index)
    }
}

impl std::fmt::Debug for ChainSetting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("ChainSetting").field(&self.flag).finish()
    }
}

impl ChainSetting {
    /// Whether it means anything under `chain` (LineAO's base radius only in its `reference`
    /// variant): a panel shows it only then.
    pub fn applies(&self, chain: &ChainSettings) -> bool {
        self.own.applies(self.index, chain)
    }

    /// Its value in `chain`.
    pub fn get(&self, chain: &ChainSettings) -> Value {
        self.own.get(self.index, chain)
    }

    /// Puts `value` (of its [`About::kind`]) into `chain`.
    pub fn set(&self, chain: &mut ChainSettings, value: Value) {
        self.own.set(self.index, chain, value)
    }
}

impl MethodInfo {
    /// Its settings as they describe themselves, from which the front ends make their flags,
    /// keywords, controls and URL keys; a chain's validation checks each value's range before
    /// the method's own validation runs.
    pub fn settings(&self) -> impl Iterator<Item = ChainSetting> + use<> {
        let own = self.own;
        (0..own.len()).map(move |index| ChainSetting { own, index })
    }

    /// Its [`MethodInfo::variant`] where `chain` has that form of it.
    pub fn variant_of(&self, chain: &ChainSettings) -> Option<&Variant> {
        let variant = self.variant.as_ref()?;
        let setting = self.settings().find(|s| s.flag == variant.setting)?;
        (setting.get(chain) == Value::Choice(variant.value)).then_some(variant)
    }

    /// What a panel calls after one of its controls moved a value of this method's: the others
    /// changed so that the settings stay valid (SSAO's sphere kernel takes only its sample
    /// counts). The command line calls nothing: what it is given is checked, not changed.
    pub fn conform(&self, chain: &mut ChainSettings) {
        self.own.conform(chain)
    }
}

/// How far from a pixel a stage reads, for the guard band (docs/reference.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reach {
    /// At most `radius_px` pixels (before any blur), on a pyramid of `levels` levels (the band
    /// is rounded to the deepest level's texel).
    Pixels {
        /// The reach in pixels.
        radius_px: f32,
        /// The pyramid's levels.
        levels: u32,
    },
    /// Without bound (it grows toward the far plane): the largest band allowed.
    Unbounded,
}

/// [`MethodInfo::fits`] of a method that allocates nothing the device could refuse.
pub(crate) fn fits_always(_: (u32, u32), _: &wgpu::Limits) -> Result<(), crate::Error> {
    Ok(())
}

/// [`MethodInfo::fits`] of a method's storage buffer of `bytes` for a guard-banded `size`:
/// more than the device's storage buffers take is [`crate::Error::TooLarge`], saying what
/// (`what`) needs it.
pub(crate) fn fits_storage(
    what: &str,
    size: (u32, u32),
    bytes: u64,
    limits: &wgpu::Limits,
) -> Result<(), crate::Error> {
    let max_storage = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    if bytes <= max_storage {
        return Ok(());
    }
    let message = format!(
        "{what} for {} x {} px (with the guard band) needs {bytes} bytes, more than the adapter's {max_storage} \
         byte storage buffers",
        size.0, size.1
    );
    Err(crate::Error::TooLarge { limit: crate::Limit::StorageBuffer, value: bytes, max: max_storage, message })
}

/// What a method does in the chain: it reads the G-buffer in [`FrameTargets`] and writes `ao`,
/// between the geometry and the composite. The timing span names are docs/reference.md's.
///
/// Why a trait object and not an enum of stage types: a stage is called a handful of times per
/// frame (not per pixel), so dynamic dispatch costs nothing measurable, and the chain, the
/// guard band and the timings follow from the trait without naming a method.
pub trait Stage: wgpu::WasmNotSendSync + std::any::Any {
    /// Whether this stage, as built, computes `settings`' method (else the chain builds another).
    fn matches(&self, settings: &ChainSettings) -> bool;
    /// How far it reads for a frame seen as `unguarded` (the frame's size, no guard band).
    fn reach(&self, settings: &ChainSettings, unguarded: &FrameView) -> Reach;
    /// The spans it records, in order, under `settings` (of its method's [`MethodInfo::spans`]).
    fn spans(&self, settings: &ChainSettings) -> &'static [&'static str];
    /// Binds newly allocated targets, and allocates at their size what the stage alone reads
    /// and writes (checked by its method's size check in the registry).
    fn resize(&mut self, device: &wgpu::Device, targets: &FrameTargets);
    /// Writes the frame's uniforms.
    fn prepare(&self, queue: &wgpu::Queue, targets: &FrameTargets, view: &FrameView, settings: &ChainSettings);
    /// Records the stage; `span(name)` times one of [`Stage::spans`].
    fn encode<'t>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        span: &dyn Fn(&'static str) -> Option<Span<'t>>,
    );
    /// The occlusion of the last frame before the stage's own blur, where it has one (SSAO's
    /// 4 × 4 box): what docs/reference.md's `ao.npy` holds and what a CPU reference of the
    /// stage's main pass is compared with. `None`: the stage writes `ao` unblurred.
    fn unblurred(&self) -> Option<&Target> {
        None
    }
    /// What `lineao render --dump` writes of the method beside the G-buffer under `settings`
    /// for the last frame, seen as `view`: docs/reference.md's keys of `params.json` and its
    /// tables (noise tiles, sample sets, pyramids read back from `gpu`).
    #[cfg(all(feature = "serde", feature = "reference"))]
    fn dump(&self, gpu: &crate::Gpu, settings: &ChainSettings, view: &FrameView) -> Result<Dump, Error> {
        let _ = (gpu, settings, view);
        Ok(Dump::default())
    }
}

/// A method's part of a `--dump` folder ([`Stage::dump`]).
#[cfg(all(feature = "serde", feature = "reference"))]
#[derive(Debug, Default)]
pub struct Dump {
    /// Keys of `params.json`.
    pub params: serde_json::Map<String, serde_json::Value>,
    /// Tables written as `NAME.npy`: the name, the shape and the values in row-major order.
    pub arrays: Vec<(String, Vec<u64>, Vec<f32>)>,
}

#[cfg(all(feature = "serde", feature = "reference"))]
impl Dump {
    /// Adds the keys of `object` (a JSON object) to the parameters.
    pub fn params(&mut self, object: serde_json::Value) {
        if let serde_json::Value::Object(keys) = object {
            self.params.extend(keys);
        }
    }

    /// Adds the table `name` of shape `shape`, its values in row-major order.
    pub fn array(&mut self, name: &str, shape: &[u64], values: Vec<f32>) {
        self.arrays.push((name.to_string(), shape.to_vec(), values));
    }
}

impl dyn Stage {
    /// This stage if it is a `T` (its own targets and state, for readback).
    pub fn downcast<T: Stage>(&self) -> Option<&T> {
        (self as &dyn std::any::Any).downcast_ref()
    }
}
