//! GPU time per pass from timestamp queries.
//!
//! A [`PassTimer`] owns a query set with two timestamps per named span. A pass records into a
//! span by putting [`Span::compute`] or [`Span::render`] into its pass descriptor's
//! `timestamp_writes` (the portable form: no timestamps between passes, which WebGPU lacks);
//! a span may start in one pass and end in a later one ([`Span::begin_only`], [`Span::end_only`]),
//! which is how a chain of passes is timed as a whole. After the commands are submitted,
//! [`PassTimer::read`] waits for them and returns each span's duration; a host that must not
//! block asks with [`PassTimer::try_read`] instead, once per frame, and gets the durations of an
//! earlier frame when the GPU has finished it (frames in between are not timed).
//!
//! Adapters without `TIMESTAMP_QUERY` get no timer ([`PassTimer::new`] returns `None`); callers
//! then fall back to CPU wall time around submit + wait, and say so.

use crate::Error;
use crate::readback::LateReadback;

/// The timestamps of one span inside a [`PassTimer`]'s query set.
#[derive(Clone, Copy)]
pub struct Span<'a> {
    query_set: &'a wgpu::QuerySet,
    begin: Option<u32>,
    end: Option<u32>,
}

impl<'a> Span<'a> {
    /// Only the start of the span: for the first of several passes.
    pub fn begin_only(self) -> Span<'a> {
        Span { end: None, ..self }
    }

    /// Only the end of the span: for the last of several passes.
    pub fn end_only(self) -> Span<'a> {
        Span { begin: None, ..self }
    }

    /// `span` over several passes: what the first records (its start, if it has one) and what
    /// the last records (its end, if it has one).
    pub fn split(span: Option<Span<'a>>) -> (Option<Span<'a>>, Option<Span<'a>>) {
        let first = span.map(Span::begin_only).filter(|s| s.begin.is_some());
        let last = span.map(Span::end_only).filter(|s| s.end.is_some());
        (first, last)
    }

    /// The timestamp writes of a compute pass.
    pub fn compute(&self) -> wgpu::ComputePassTimestampWrites<'a> {
        wgpu::ComputePassTimestampWrites {
            query_set: self.query_set,
            beginning_of_pass_write_index: self.begin,
            end_of_pass_write_index: self.end,
        }
    }

    /// The timestamp writes of a render pass.
    pub fn render(&self) -> wgpu::RenderPassTimestampWrites<'a> {
        wgpu::RenderPassTimestampWrites {
            query_set: self.query_set,
            beginning_of_pass_write_index: self.begin,
            end_of_pass_write_index: self.end,
        }
    }
}

/// `span.compute()` for an optional span.
pub fn compute_writes<'a>(span: Option<Span<'a>>) -> Option<wgpu::ComputePassTimestampWrites<'a>> {
    span.map(|s| s.compute())
}

/// `span.render()` for an optional span.
pub fn render_writes<'a>(span: Option<Span<'a>>) -> Option<wgpu::RenderPassTimestampWrites<'a>> {
    span.map(|s| s.render())
}

/// Duration of one named span, in milliseconds.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTime {
    /// The span's name (`lineao bench`'s pass names).
    pub name: &'static str,
    /// Its duration in ms.
    pub ms: f64,
}

/// Timestamp queries for a fixed list of named spans.
pub struct PassTimer {
    names: Vec<&'static str>,
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: LateReadback,
    period_ns: f64,
}

impl PassTimer {
    /// A timer for `names`, or `None` when the device has no timestamp queries.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, names: &[&'static str]) -> Option<PassTimer> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) || names.is_empty() {
            return None;
        }
        let count = 2 * names.len() as u32;
        let bytes = count as u64 * wgpu::QUERY_SIZE as u64;
        Some(PassTimer {
            names: names.to_vec(),
            query_set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("lineao::PassTimer::queries"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lineao::PassTimer::resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: LateReadback::new(device, "lineao::PassTimer::readback", bytes),
            period_ns: queue.get_timestamp_period() as f64,
        })
    }

    /// The span called `name`; `None` if the timer has no such span.
    pub fn span(&self, name: &str) -> Option<Span<'_>> {
        let index = self.names.iter().position(|n| *n == name)? as u32;
        Some(Span { query_set: &self.query_set, begin: Some(2 * index), end: Some(2 * index + 1) })
    }

    /// Records the copy of every timestamp to the CPU-readable buffer, mapped for reading once
    /// the frame has run (`map_buffer_on_submit`); call once per frame after the timed passes.
    /// While an earlier frame's timestamps wait to be read, this frame's are resolved but not
    /// copied: that frame is not timed. A timed frame recorded but never submitted stops the
    /// timings until the timer is made again.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        let count = 2 * self.names.len() as u32;
        encoder.resolve_query_set(&self.query_set, 0..count, &self.resolve, 0);
        self.readback.copy(encoder, &self.resolve);
    }

    /// Waits for the submitted frame and returns the duration of every span it wrote, in the
    /// order of `names`. A span that was not recorded this frame reads as garbage: only ask for
    /// the spans the frame used (`only`), or all when `only` is empty.
    pub fn read(&self, device: &wgpu::Device, only: &[&str]) -> Result<Vec<PassTime>, Error> {
        let bytes = self.readback.take(device)?.ok_or_else(|| Error::Gpu("no timed frame was submitted".into()))?;
        Ok(self.times(&bytes, only))
    }

    /// Never waits: the durations of the last timed frame once the GPU has finished it, else
    /// `None` (ask again next frame).
    pub fn try_read(&self, device: &wgpu::Device, only: &[&str]) -> Result<Option<Vec<PassTime>>, Error> {
        Ok(self.readback.try_take(device)?.map(|bytes| self.times(&bytes, only)))
    }

    /// The spans' durations from the resolved timestamps.
    fn times(&self, bytes: &[u8], only: &[&str]) -> Vec<PassTime> {
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(bytes);
        self.names
            .iter()
            .enumerate()
            .filter(|(_, name)| only.is_empty() || only.contains(name))
            .map(|(i, &name)| PassTime {
                name,
                ms: ticks[2 * i + 1].wrapping_sub(ticks[2 * i]) as f64 * self.period_ns * 1e-6,
            })
            .collect()
    }
}
