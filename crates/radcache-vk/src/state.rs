//! What a [`Recorder`] knows about its own command stream, so that the safe recording functions
//! check their preconditions instead of leaving them to the caller.
//!
//! wgpu-hal writes such preconditions down as the contract of an `unsafe fn`. radcache's callers
//! (`radcache-render`) forbid `unsafe`, so here they are checked at record time, and a violation
//! panics with a message naming the call, the pipeline and the resource: recording a draw outside
//! a rendering, an indirect call past the end of its buffer or a dispatch with a declared binding
//! never pushed is a programming error, never a condition of the input. What cannot be checked on
//! the host (values the GPU itself writes into indirect arguments) is listed on the function that
//! consumes it.
//!
//! The state tracked per recording:
//! - the bound pipeline, with the bindings pushed and whether push constants were set since it was
//!   bound (binding another pipeline starts both afresh: push descriptors and push constants do
//!   not survive a layout change);
//! - the open rendering (its attachment formats), if any;
//! - the bound index buffer (how many indices it holds past its offset);
//! - the resources it touched and the renderings it began, for the derived barriers
//!   (`hazard.rs`; each resource's own track lives in the resource).

use ash::vk;

use crate::buffer::Buffer;
use crate::commands::Recorder;
use crate::hazard::{lock, Target, Tracked, Use};
use crate::pipeline::{BindingLayout, Pipeline};

/// A resource pushed as a descriptor and its use by the bound pipeline's shaders.
#[derive(Debug, Clone)]
pub(crate) struct Pushed {
    pub binding: u32,
    pub target: Target,
    pub use_: Use,
}

/// The pipeline bound last and what was pushed for it since.
#[derive(Debug, Clone)]
pub(crate) struct BoundPipeline {
    pub bind_point: vk::PipelineBindPoint,
    pub layout: vk::PipelineLayout,
    pub bindings: Vec<BindingLayout>,
    pub push_constant_size: u32,
    pub stages: vk::ShaderStageFlags,
    pub name: String,
    /// Attachment formats of a graphics pipeline (empty and `UNDEFINED` for compute).
    pub color_formats: Vec<vk::Format>,
    pub depth_format: vk::Format,
    /// Binding numbers pushed since `bind_pipeline`.
    pub pushed: Vec<u32>,
    /// Whether `push_constants` was called since `bind_pipeline`.
    pub constants_set: bool,
    /// Binding numbers the shaders may write (the rest they only read).
    pub written: Vec<u32>,
    /// The tracked resources among the pushed bindings (a binding pushed again replaces its
    /// entry): their barriers are derived at the next dispatch (compute) or at the push
    /// (graphics: before the rendering begins).
    pub uses: Vec<Pushed>,
}

impl BoundPipeline {
    pub fn new(p: &Pipeline) -> Self {
        BoundPipeline {
            bind_point: p.bind_point,
            layout: p.layout,
            bindings: p.bindings.clone(),
            push_constant_size: p.push_constant_size,
            stages: p.stages,
            name: p.name().to_string(),
            color_formats: p.color_formats.clone(),
            depth_format: p.depth_format,
            pushed: Vec::new(),
            constants_set: false,
            written: p.written.clone(),
            uses: Vec::new(),
        }
    }

    /// Declared bindings not pushed since the pipeline was bound.
    fn missing(&self) -> Vec<u32> {
        self.bindings
            .iter()
            .map(|b| b.binding)
            .filter(|b| !self.pushed.contains(b))
            .collect()
    }
}

/// The open rendering: the formats its pipelines must have been created for.
#[derive(Debug, Clone)]
pub(crate) struct Rendering {
    pub color_formats: Vec<vk::Format>,
    pub depth_format: vk::Format,
}

/// The bound index buffer.
#[derive(Debug, Clone)]
pub(crate) struct IndexBuffer {
    pub name: String,
    /// `u32` indices between the bound offset and the end of the buffer.
    pub count: u64,
}

/// Everything a recording tracks for its checks.
#[derive(Debug, Default)]
pub(crate) struct RecordState {
    pub bound: Option<BoundPipeline>,
    pub rendering: Option<Rendering>,
    pub index: Option<IndexBuffer>,
    /// Resources whose track this recording changed (reset if it is abandoned).
    pub touched: Vec<Tracked>,
    /// Renderings begun so far (numbering them from 1 for the tracks).
    pub renderings: u64,
    /// Whether any command so far may write (the end of the recording then makes the device's
    /// writes visible to the host).
    pub wrote: bool,
}

impl Recorder {
    /// The bound pipeline (any kind); panics naming `call` when none is.
    pub(crate) fn bound_for(&self, call: &str) -> &BoundPipeline {
        self.state
            .bound
            .as_ref()
            .unwrap_or_else(|| panic!("{call}: no pipeline is bound (bind_pipeline first)"))
    }

    /// Checks that a compute pipeline is bound with everything pushed and no rendering is open.
    pub(crate) fn check_dispatch(&self, call: &str) {
        let bound = self.bound_for(call);
        assert!(
            bound.bind_point == vk::PipelineBindPoint::COMPUTE,
            "{call}: pipeline {:?} is a graphics pipeline, not a compute one",
            bound.name
        );
        assert!(
            self.state.rendering.is_none(),
            "{call} with pipeline {:?}: a rendering is open (end_rendering first)",
            bound.name
        );
        check_pushed(bound, call);
    }

    /// Checks that a graphics pipeline matching the open rendering is bound with everything pushed.
    pub(crate) fn check_draw(&self, call: &str) {
        let bound = self.bound_for(call);
        assert!(
            bound.bind_point == vk::PipelineBindPoint::GRAPHICS,
            "{call}: pipeline {:?} is a compute pipeline, not a graphics one",
            bound.name
        );
        let rendering = self.state.rendering.as_ref().unwrap_or_else(|| {
            panic!(
                "{call} with pipeline {:?}: no rendering is open (begin_rendering first)",
                bound.name
            )
        });
        assert!(
            rendering.color_formats == bound.color_formats
                && rendering.depth_format == bound.depth_format,
            "{call}: pipeline {:?} renders to colours {:?} and depth {:?}, the open rendering has \
             colours {:?} and depth {:?}",
            bound.name,
            bound.color_formats,
            bound.depth_format,
            rendering.color_formats,
            rendering.depth_format
        );
        check_pushed(bound, call);
    }

    /// Checks that every image pushed for the bound pipeline is in its descriptor's layout (the
    /// derived transitions put it there: a failure here is a bug of `hazard.rs`).
    pub(crate) fn check_layouts(&self, call: &str) {
        let bound = self.bound_for(call);
        for pushed in &bound.uses {
            let (track, want) = (lock(&pushed.target.track), pushed.use_.layout);
            assert!(
                want.is_none_or(|l| l == track.layout),
                "{call} with pipeline {:?}: image {:?} at binding {} is in layout {:?}, its \
             descriptor expects {want:?} (a derived transition is missing)",
                bound.name,
                pushed.target.name,
                pushed.binding,
                track.layout
            );
        }
    }

    /// Panics when a rendering is open: `call` is only valid outside one.
    pub(crate) fn check_outside_rendering(&self, call: &str) {
        assert!(
            self.state.rendering.is_none(),
            "{call} in recording {:?}: not allowed inside a rendering (end_rendering first)",
            self.label
        );
    }

    /// Checks an indirect call's argument buffer: INDIRECT_BUFFER usage, `offset` a multiple of
    /// 4, and `bytes` of arguments from `offset` inside the buffer.
    pub(crate) fn check_indirect(&self, call: &str, args: &Buffer, offset: u64, bytes: u64) {
        let pipeline = &self.bound_for(call).name;
        assert!(
            args.usage().contains(vk::BufferUsageFlags::INDIRECT_BUFFER),
            "{call} with pipeline {pipeline:?}: buffer {:?} was not created with INDIRECT_BUFFER \
             usage",
            args.name()
        );
        assert!(
            offset.is_multiple_of(4),
            "{call} with pipeline {pipeline:?}: offset {offset} into buffer {:?} is not a \
             multiple of 4",
            args.name()
        );
        assert!(
            offset
                .checked_add(bytes)
                .is_some_and(|end| end <= args.size()),
            "{call} with pipeline {pipeline:?}: {bytes} bytes of arguments at offset {offset} run \
             past the end of buffer {:?} ({} bytes)",
            args.name(),
            args.size()
        );
    }
}

/// Every declared binding pushed, push constants set when the layout has any.
fn check_pushed(bound: &BoundPipeline, call: &str) {
    let missing = bound.missing();
    assert!(
        missing.is_empty(),
        "{call} with pipeline {:?}: declared binding(s) {missing:?} not pushed since bind_pipeline",
        bound.name
    );
    assert!(
        bound.push_constant_size == 0 || bound.constants_set,
        "{call} with pipeline {:?}: its {} bytes of push constants were not set since \
         bind_pipeline",
        bound.name,
        bound.push_constant_size
    );
}
