//! Barriers and image layouts derived from what each command reads and writes.
//!
//! A pass never places a barrier. Every command that touches a resource states its use of it —
//! a dispatch or draw through the bindings it pushed (each binding read-only or read-write as
//! its shader declares it, read off the SPIR-V by `reflect.rs`), a copy or fill through its source
//! and destination, a rendering through its attachments, an indirect call through its argument
//! buffer — and the recorder compares that use with what the resource's [`Track`] says happened
//! to it last. A read after a write gets a memory dependency, a write after reads an execution
//! dependency, a write after a write both, a new layout a transition; a read after reads, or a
//! second read of a write already made visible to that stage, gets nothing. This is the record-time
//! half of a frame graph (kajiya's passes declare their reads and writes the same way): the
//! order of the commands is the caller's, the synchronization between them is derived.
//!
//! The track lives in the resource, not in the recording, so it carries across recordings; they
//! must reach the queue in the order they were recorded (checked: a resource last used by a
//! recording that is still open cannot be used by another). A pipeline barrier's first scope
//! covers everything submitted earlier to the queue, so a dependency on a use in an earlier,
//! submitted recording is sound. At the end of a recording that wrote anything, one global barrier
//! makes the device's writes visible to the host, for read-backs after the wait. A transition into
//! a read-only layout is made visible to every shader stage at once, so that readers in other
//! stages need no second barrier. What the tracks do not see — acceleration structures, built and
//! read through device addresses — keeps its explicit barriers in `accel.rs` and `tlas.rs`.
//!
//! The layer's synchronization validation (`RADCACHE_VALIDATION=sync`, on for `cargo xtask test`)
//! checks the derivation: a hazard no derived barrier orders is a validation error.
//!
//! Inside a rendering no barrier may be recorded, so what the draws use is prepared before it
//! begins: the attachments by `begin_rendering`, the bindings by pushing them before it, the
//! indirect arguments by naming them in [`crate::RenderTargets::indirect`], the index buffer by
//! binding it before it. A draw whose resource
//! would still need a barrier panics with the name of the resource. Uses by several draws of one
//! rendering are not ordered against each other (blending and the draws' own atomics are the
//! shaders' business, as in any renderer).

use std::sync::{Arc, Mutex};

use ash::vk;

use crate::commands::Recorder;
use crate::sync::Access;

type S = vk::PipelineStageFlags2;
type A = vk::AccessFlags2;

/// A resource's tracked state, shared between the resource and the recordings that use it.
pub(crate) type Tracked = Arc<Mutex<Track>>;

/// Locks a track (a panic while it was held leaves it usable: it is plain data).
pub(crate) fn lock(t: &Tracked) -> std::sync::MutexGuard<'_, Track> {
    t.lock().unwrap_or_else(|p| p.into_inner())
}

/// What happened to a resource last, as far as the next barrier needs it.
#[derive(Debug, Clone)]
pub(crate) struct Track {
    /// The layout it will be in once everything recorded so far has executed (images only;
    /// buffers stay `UNDEFINED`).
    pub layout: vk::ImageLayout,
    /// The stages and write accesses of the last write (`Access::NONE`: none since creation, or
    /// one already ordered before every later use).
    pub write: Access,
    /// Stages and accesses the last write has been made visible to since.
    pub visible: Vec<Access>,
    /// Stages that read it since the last write.
    pub reads: vk::PipelineStageFlags2,
    /// The recording that used it last (0: none yet).
    pub recording: u64,
    /// The rendering (numbered per recording, from 1) whose draws use it; 0: none.
    pub rendering: u64,
}

impl Track {
    /// A new resource: `UNDEFINED`, never used.
    pub fn new() -> Self {
        Track {
            layout: vk::ImageLayout::UNDEFINED,
            write: Access::NONE,
            visible: Vec::new(),
            reads: S::NONE,
            recording: 0,
            rendering: 0,
        }
    }

    /// A new shared track.
    pub fn shared() -> Tracked {
        Arc::new(Mutex::new(Track::new()))
    }
}

/// One command's use of a resource.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Use {
    /// The stages and accesses (reads and writes) of the use.
    pub access: Access,
    /// Whether it may write.
    pub writes: bool,
    /// The layout an image must be in (`None` for buffers).
    pub layout: Option<vk::ImageLayout>,
}

impl Use {
    /// A read at `access`.
    pub const fn read(access: Access) -> Use {
        Use {
            access,
            writes: false,
            layout: None,
        }
    }

    /// A write (or read-modify-write) at `access`.
    pub const fn write(access: Access) -> Use {
        Use {
            access,
            writes: true,
            layout: None,
        }
    }

    /// The same use of an image in `layout`.
    pub const fn in_layout(self, layout: vk::ImageLayout) -> Use {
        Use {
            layout: Some(layout),
            ..self
        }
    }

    /// Both uses by one command (the union of accesses, writing if either does; the layouts must
    /// agree).
    pub fn merge(self, other: Use) -> Use {
        Use {
            access: self.access.union(other.access),
            writes: self.writes || other.writes,
            layout: self.layout.or(other.layout),
        }
    }
}

/// The barrier one resource needs before a use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Dep {
    pub src: Access,
    pub dst: Access,
    /// The transition (old, new) of an image whose layout changes.
    pub layouts: Option<(vk::ImageLayout, vk::ImageLayout)>,
}

/// The write accesses among `a` (the ones a barrier's source needs).
const fn writes_of(a: A) -> A {
    A::from_raw(
        a.as_raw()
            & (A::SHADER_STORAGE_WRITE.as_raw()
                | A::SHADER_WRITE.as_raw()
                | A::COLOR_ATTACHMENT_WRITE.as_raw()
                | A::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
                | A::TRANSFER_WRITE.as_raw()
                | A::HOST_WRITE.as_raw()
                | A::MEMORY_WRITE.as_raw()
                | A::ACCELERATION_STRUCTURE_WRITE_KHR.as_raw()),
    )
}

/// Every shader stage's reads: the destination of a transition into a read-only layout, so that
/// any later reader in any stage is ordered after it without another barrier.
const ANY_SHADER_READ: Access = Access::new(
    S::from_raw(
        S::COMPUTE_SHADER.as_raw() | S::VERTEX_SHADER.as_raw() | S::FRAGMENT_SHADER.as_raw(),
    ),
    A::from_raw(
        A::SHADER_STORAGE_READ.as_raw()
            | A::SHADER_SAMPLED_READ.as_raw()
            | A::UNIFORM_READ.as_raw(),
    ),
);

fn covers(outer: Access, inner: Access) -> bool {
    outer.stage.contains(inner.stage) && outer.access.contains(inner.access)
}

impl Track {
    /// The barrier `u` needs after what the track records (`None`: none), and the track updated
    /// as if that barrier and the use had been recorded.
    pub fn require(&mut self, u: Use) -> Option<Dep> {
        let old_layout = self.layout;
        let transition = u.layout.filter(|l| *l != old_layout);
        let pending = !self.write.stage.is_empty();
        let dep = if u.writes || transition.is_some() {
            let src = Access::new(self.write.stage | self.reads, self.write.access);
            let read_only_layout = transition.is_some() && !u.writes;
            let dst = if read_only_layout && u.access.stage.intersects(ANY_SHADER_READ.stage) {
                u.access.union(ANY_SHADER_READ)
            } else {
                u.access
            };
            (pending || !self.reads.is_empty() || transition.is_some()).then_some(Dep {
                src,
                dst,
                layouts: transition.map(|new| (old_layout, new)),
            })
        } else {
            let seen = self.visible.iter().any(|v| covers(*v, u.access));
            (pending && !seen).then_some(Dep {
                src: self.write,
                dst: u.access,
                layouts: None,
            })
        };
        if let Some(l) = u.layout {
            self.layout = l;
        }
        if u.writes {
            self.write = Access::new(u.access.stage, writes_of(u.access.access));
            self.visible.clear();
            self.reads = S::NONE;
        } else if let Some(d) = dep.filter(|d| d.layouts.is_some()) {
            // A transition for readers: it is ordered before `d.dst`, every shader stage's reads
            // (or the one transfer read), so later readers need nothing more.
            self.write = Access::NONE;
            self.visible.clear();
            self.reads = d.dst.stage;
        } else {
            if let Some(d) = dep {
                if self.visible.len() >= 4 {
                    self.visible.remove(0);
                }
                self.visible.push(d.dst);
            }
            self.reads |= u.access.stage;
        }
        dep
    }
}

/// A tracked resource as a barrier names it: made once with the resource, so that a use borrows it
/// and allocates nothing.
#[derive(Debug, Clone)]
pub(crate) struct Target {
    pub name: Arc<str>,
    pub track: Tracked,
    /// The image and its subresources (`None` for a buffer).
    pub image: Option<(vk::Image, vk::ImageSubresourceRange)>,
}

impl Target {
    /// A new resource's target, with a fresh track.
    pub fn new(name: &str, image: Option<(vk::Image, vk::ImageSubresourceRange)>) -> Target {
        Target {
            name: name.into(),
            track: Track::shared(),
            image,
        }
    }
}

impl crate::buffer::Buffer {
    pub(crate) fn target(&self) -> &Target {
        &self.target
    }
}

impl crate::image::Image {
    pub(crate) fn target(&self) -> &Target {
        &self.target
    }
}

/// Which rendering a use belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scope {
    /// A command outside any rendering (a dispatch, a copy).
    Outside,
    /// What the draws of the next rendering will use, prepared before it begins.
    NextRendering,
    /// A draw (or a push) inside the open rendering: nothing may need a barrier.
    InRendering,
}

impl Recorder {
    /// `outside` outside a rendering; inside one, [`Scope::InRendering`].
    pub(crate) fn scope_or(&self, outside: Scope) -> Scope {
        if self.state.rendering.is_some() {
            Scope::InRendering
        } else {
            outside
        }
    }

    /// Records the barriers `uses` need after what their resources' tracks say, and updates the
    /// tracks. `call` names the command in a panic: inside a rendering (`Scope::InRendering`), a
    /// use that would need a barrier (its resource was not prepared before the rendering began).
    pub(crate) fn sync(&mut self, call: &str, scope: Scope, uses: &[(&Target, Use)]) {
        let mut merged: Vec<(&Target, Use)> = Vec::with_capacity(uses.len());
        for &(t, u) in uses {
            match merged
                .iter_mut()
                .find(|(m, _)| Arc::ptr_eq(&m.track, &t.track))
            {
                Some((_, m)) => *m = m.merge(u),
                None => merged.push((t, u)),
            }
        }
        let tag = match scope {
            Scope::Outside => 0,
            Scope::NextRendering => self.state.renderings + 1,
            Scope::InRendering => self.state.renderings,
        };
        let mut global: Option<(Access, Access)> = None;
        let mut images = Vec::new();
        for (target, u) in merged {
            let mut track = lock(&target.track);
            assert!(
                track.recording == self.index || !self.shared.is_unsubmitted(track.recording),
                "{call} in recording {:?}: {:?} was last used by recording {}, which is still \
                 open (submit or drop it first: barriers are derived in record order)",
                self.label,
                target.name,
                track.recording
            );
            if scope == Scope::InRendering
                && track.rendering == tag
                && track.recording == self.index
            {
                continue;
            }
            if track.recording != self.index {
                self.state.touched.push(target.track.clone());
                track.recording = self.index;
            }
            self.state.wrote |= u.writes;
            let dep = track.require(u);
            track.rendering = tag;
            let Some(dep) = dep else { continue };
            assert!(
                scope != Scope::InRendering,
                "{call} in recording {:?}: {:?} needs a barrier ({:?} before {:?}) inside a \
                 rendering; push the draws' bindings, bind their index buffer and name their \
                 indirect arguments before begin_rendering",
                self.label,
                target.name,
                dep.src,
                dep.dst
            );
            match (target.image, dep.layouts) {
                (Some((image, range)), layouts) => {
                    let (old, new) = layouts.unwrap_or((track.layout, track.layout));
                    images.push(
                        vk::ImageMemoryBarrier2::default()
                            .src_stage_mask(dep.src.stage)
                            .src_access_mask(dep.src.access)
                            .dst_stage_mask(dep.dst.stage)
                            .dst_access_mask(dep.dst.access)
                            .old_layout(old)
                            .new_layout(new)
                            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                            .image(image)
                            .subresource_range(range),
                    );
                }
                (None, _) => {
                    let (src, dst) = global.unwrap_or((Access::NONE, Access::NONE));
                    global = Some((src.union(dep.src), dst.union(dep.dst)));
                }
            }
        }
        let memory: Vec<_> = global
            .into_iter()
            .map(|(src, dst)| {
                vk::MemoryBarrier2::default()
                    .src_stage_mask(src.stage)
                    .src_access_mask(src.access)
                    .dst_stage_mask(dst.stage)
                    .dst_access_mask(dst.access)
            })
            .collect();
        if memory.is_empty() && images.is_empty() {
            return;
        }
        let info = vk::DependencyInfo::default()
            .memory_barriers(&memory)
            .image_memory_barriers(&images);
        // SAFETY: recording outside a rendering (a use inside one that needs a barrier panics
        // above); every image barrier names a live image of this device (kept by the graveyard
        // until the recording ends) with its full subresource range and the layout its track
        // holds; `info` and its arrays outlive the call.
        unsafe { self.shared.device.cmd_pipeline_barrier2(self.cmd, &info) };
    }

    /// Makes every device write of this recording visible to the host (the end of a recording
    /// that wrote anything: read-backs follow the wait).
    pub(crate) fn sync_host(&mut self) {
        if !self.state.wrote {
            return;
        }
        let barrier = [vk::MemoryBarrier2::default()
            .src_stage_mask(S::ALL_COMMANDS)
            .src_access_mask(A::MEMORY_WRITE)
            .dst_stage_mask(S::HOST)
            .dst_access_mask(A::HOST_READ)];
        let info = vk::DependencyInfo::default().memory_barriers(&barrier);
        // SAFETY: recording outside a rendering (`submit` checks); `info` outlives the call.
        unsafe { self.shared.device.cmd_pipeline_barrier2(self.cmd, &info) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const COMPUTE_READ: Access = Access::new(S::COMPUTE_SHADER, A::SHADER_STORAGE_READ);
    const COMPUTE_WRITE: Access = Access::new(S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE);
    const RASTER_READ: Access = Access::new(
        S::from_raw(S::VERTEX_SHADER.as_raw() | S::FRAGMENT_SHADER.as_raw()),
        A::SHADER_STORAGE_READ,
    );
    const CW: Use = Use::write(COMPUTE_READ.union(COMPUTE_WRITE));
    const CR: Use = Use::read(COMPUTE_READ);

    #[test]
    fn read_after_write_gets_one_memory_dependency_per_stage() {
        let mut t = Track::new();
        assert_eq!(t.require(CW), None, "a fresh buffer needs nothing");
        let d = t.require(CR).expect("read after write");
        assert_eq!(d.src, COMPUTE_WRITE);
        assert_eq!(d.dst, COMPUTE_READ);
        assert_eq!(
            t.require(CR),
            None,
            "the write is visible to compute reads already"
        );
        let raster = Use::read(RASTER_READ);
        let d = t
            .require(raster)
            .expect("another stage needs its own visibility");
        assert_eq!(d.src, COMPUTE_WRITE);
        assert_eq!(t.require(raster), None);
    }

    #[test]
    fn write_after_reads_waits_for_the_readers() {
        let mut t = Track::new();
        t.require(CW);
        t.require(CR);
        t.require(Use::read(Access::INDIRECT));
        let d = t.require(Use::write(Access::TRANSFER_WRITE)).expect("WAR");
        assert!(d.src.stage.contains(S::COMPUTE_SHADER | S::DRAW_INDIRECT));
        assert_eq!(d.dst, Access::TRANSFER_WRITE);
        let d = t.require(Use::write(Access::TRANSFER_WRITE)).expect("WAW");
        assert_eq!(d.src, Access::TRANSFER_WRITE);
    }

    #[test]
    fn reads_after_reads_need_nothing() {
        let mut t = Track::new();
        assert_eq!(t.require(CR), None);
        assert_eq!(t.require(Use::read(RASTER_READ)), None);
        assert_eq!(t.require(Use::read(Access::TRANSFER_READ)), None);
    }

    #[test]
    fn transitions_follow_the_layout() {
        let mut t = Track::new();
        let general = CW.in_layout(vk::ImageLayout::GENERAL);
        let d = t.require(general).expect("UNDEFINED to GENERAL");
        assert_eq!(
            d.layouts,
            Some((vk::ImageLayout::UNDEFINED, vk::ImageLayout::GENERAL))
        );
        let sampled = CR.in_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        let d = t.require(sampled).expect("GENERAL to read-only");
        assert_eq!(d.src, COMPUTE_WRITE);
        assert!(covers(d.dst, RASTER_READ), "{d:?}");
        let raster = Use::read(RASTER_READ).in_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        assert_eq!(
            t.require(raster),
            None,
            "the transition reached every shader stage"
        );
        let d = t.require(general).expect("back to GENERAL after reads");
        assert!(d.src.stage.contains(S::FRAGMENT_SHADER | S::COMPUTE_SHADER));
        assert_eq!(d.src.access, A::NONE);
    }
}
