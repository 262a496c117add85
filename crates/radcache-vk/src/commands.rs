//! Command recording and submission.
//!
//! A [`Recorder`] owns one command buffer and the profiler state of that recording. Passes are
//! recorded inside `rec.pass(NAME, |rec| ...)`, which gives each a timestamp pair and a debug label.
//! [`Context::submit`] hands the recording to the queue with a fence; [`Submission::wait`] waits,
//! reads the timings, and lets the graveyard destroy what the recording kept alive.

use std::ffi::CString;
use std::sync::Arc;

use ash::vk;

use crate::context::{Context, DeviceShared, Garbage};
use crate::error::{Error, Result, VkResultExt};
use crate::profiler::{PassTiming, ProfilerRecording, Scope, MAX_QUERIES};

/// An open command recording. Dropping it unsubmitted abandons the commands.
pub struct Recorder {
    pub(crate) shared: Arc<DeviceShared>,
    pub(crate) cmd: vk::CommandBuffer,
    /// This recording's index (`DeviceShared::begin_recording`), which buffers remember.
    pub(crate) index: u64,
    pub(crate) profiler: ProfilerRecording,
    /// The bound pipeline, the open rendering and the index buffer, for the record-time checks.
    pub(crate) state: crate::state::RecordState,
    pub(crate) label: String,
    finished: bool,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("label", &self.label)
            .finish()
    }
}

impl Context {
    /// Starts a command recording named `label`.
    pub fn begin(&self, label: &str) -> Result<Recorder> {
        let shared = self.shared.clone();
        let cmd = {
            let pool = shared.lock_command_pool();
            let info = vk::CommandBufferAllocateInfo::default()
                .command_pool(*pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1);
            // SAFETY: the pool is locked (externally synchronized) and live.
            unsafe { shared.device.allocate_command_buffers(&info) }
                .call("vkAllocateCommandBuffers")?[0]
        };
        let index = shared.begin_recording();
        let profiler = match ProfilerRecording::new(&shared) {
            Ok(p) => p,
            Err(e) => {
                shared.retire(Garbage::CommandBuffer(cmd));
                shared.end_recording(index);
                return Err(e);
            }
        };
        let rec = Recorder {
            shared,
            cmd,
            index,
            profiler,
            state: crate::state::RecordState::default(),
            label: label.to_string(),
            finished: false,
        };
        let info = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: `cmd` is a fresh primary command buffer owned by this recorder.
        unsafe { rec.shared.device.begin_command_buffer(cmd, &info) }
            .call("vkBeginCommandBuffer")?;
        // SAFETY: the command buffer is recording; the pool has MAX_QUERIES queries.
        unsafe {
            rec.shared
                .device
                .cmd_reset_query_pool(cmd, rec.profiler.pool, 0, MAX_QUERIES)
        };
        rec.shared.set_name(cmd, label);
        Ok(rec)
    }

    /// Submits a recording; the returned [`Submission`] must be waited for to get timings.
    pub fn submit(&self, mut rec: Recorder) -> Result<Submission> {
        assert!(
            rec.profiler.stack.is_empty(),
            "recording {:?} submitted with open pass scopes",
            rec.label
        );
        assert!(
            rec.state.rendering.is_none(),
            "recording {:?} submitted with an open rendering (end_rendering first)",
            rec.label
        );
        rec.sync_host();
        let shared = rec.shared.clone();
        // SAFETY: the command buffer is in the recording state, outside a rendering, with every
        // scope (debug label) closed (both asserted above).
        unsafe { shared.device.end_command_buffer(rec.cmd) }.call("vkEndCommandBuffer")?;
        // SAFETY: the device is live.
        let fence = unsafe {
            shared
                .device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .call("vkCreateFence")?;
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(rec.cmd)];
        let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
        let result = {
            let queue = shared.lock_queue();
            // SAFETY: the queue is locked; the command buffer is executable; the fence unsignalled.
            unsafe { shared.device.queue_submit2(*queue, &submit, fence) }
        };
        rec.finished = true;
        if result.is_ok() {
            shared.mark_submitted(rec.index);
        }
        let profiler = std::mem::replace(
            &mut rec.profiler,
            ProfilerRecording {
                pool: vk::QueryPool::null(),
                next_query: 0,
                scopes: Vec::new(),
                stack: Vec::new(),
                overflow_warned: false,
            },
        );
        let submission = Submission {
            shared: shared.clone(),
            fence,
            cmd: rec.cmd,
            index: rec.index,
            profiler,
            waited: false,
        };
        if let Err(e) = result {
            // Never reached the queue: nothing to wait for.
            let mut s = submission;
            s.release();
            return Err(Error::Vk {
                call: "vkQueueSubmit2",
                result: e,
            });
        }
        Ok(submission)
    }
}

impl Recorder {
    /// Records `f` inside a named pass scope: a debug label and a timestamp pair.
    pub fn pass<R>(&mut self, name: &str, f: impl FnOnce(&mut Self) -> R) -> R {
        self.begin_scope(name);
        let r = f(self);
        self.end_scope();
        r
    }

    fn begin_scope(&mut self, name: &str) {
        if let (Some(du), Ok(cname)) = (&self.shared.debug_utils, CString::new(name)) {
            let label = vk::DebugUtilsLabelEXT::default().label_name(&cname);
            // SAFETY: the command buffer is recording; `label` outlives the call.
            unsafe { du.cmd_begin_debug_utils_label(self.cmd, &label) };
        }
        let begin = self.profiler.take_query();
        if let Some(q) = begin {
            // SAFETY: recording; `q` was reset at the start of this command buffer.
            unsafe {
                self.shared.device.cmd_write_timestamp2(
                    self.cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    self.profiler.pool,
                    q,
                )
            };
        }
        let depth = self.profiler.stack.len() as u32;
        self.profiler.scopes.push(Scope {
            name: name.to_string(),
            depth,
            begin,
            end: None,
        });
        self.profiler.stack.push(self.profiler.scopes.len() - 1);
        *self
            .shared
            .last_pass
            .lock()
            .unwrap_or_else(|p| p.into_inner()) = Some(name.to_string());
    }

    fn end_scope(&mut self) {
        let Some(i) = self.profiler.stack.pop() else {
            return;
        };
        let has_begin = self.profiler.scopes[i].begin.is_some();
        let end = if has_begin {
            self.profiler.take_query()
        } else {
            None
        };
        if let Some(q) = end {
            // SAFETY: recording; `q` was reset at the start of this command buffer.
            unsafe {
                self.shared.device.cmd_write_timestamp2(
                    self.cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    self.profiler.pool,
                    q,
                )
            };
        }
        self.profiler.scopes[i].end = end;
        if let Some(du) = &self.shared.debug_utils {
            // SAFETY: recording; a label was begun by the matching `begin_scope`.
            unsafe { du.cmd_end_debug_utils_label(self.cmd) };
        }
    }

    /// The names of the scopes recorded so far, in order.
    pub fn scope_names(&self) -> Vec<String> {
        self.profiler
            .scopes
            .iter()
            .map(|s| s.name.clone())
            .collect()
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        if !self.finished {
            // Abandoned: the command buffer never reached the queue, so the uses and layouts its
            // tracks recorded never happened; UNDEFINED is always a valid old layout, and a
            // barrier after every earlier write is always sound.
            for tracked in &self.state.touched {
                let mut track = crate::hazard::lock(tracked);
                if track.recording == self.index {
                    *track = crate::hazard::Track::new();
                    track.write = crate::sync::Access::ALL_WRITES;
                }
            }
            self.shared.retire(Garbage::CommandBuffer(self.cmd));
            self.shared.retire(Garbage::QueryPool(self.profiler.pool));
            self.shared.end_recording(self.index);
        }
    }
}

/// A submitted recording. Waiting is required to read timings; dropping waits too.
pub struct Submission {
    shared: Arc<DeviceShared>,
    fence: vk::Fence,
    cmd: vk::CommandBuffer,
    index: u64,
    profiler: ProfilerRecording,
    waited: bool,
}

impl std::fmt::Debug for Submission {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Submission")
            .field("index", &self.index)
            .finish()
    }
}

impl Submission {
    /// Waits for the GPU to finish and returns the time of every pass scope, in record order.
    pub fn wait(mut self) -> Result<Vec<PassTiming>> {
        // SAFETY: the fence was submitted with the command buffer.
        let waited = unsafe {
            self.shared
                .device
                .wait_for_fences(&[self.fence], true, u64::MAX)
        };
        let result = match waited {
            Ok(()) => self.profiler.resolve(&self.shared),
            Err(vk::Result::ERROR_DEVICE_LOST) => Err(Error::DeviceLost {
                last_pass: self.profiler.current_name(),
            }),
            Err(e) => Err(Error::Vk {
                call: "vkWaitForFences",
                result: e,
            }),
        };
        self.waited = true;
        self.release();
        result
    }

    fn release(&mut self) {
        self.waited = true;
        self.shared.retire(Garbage::CommandBuffer(self.cmd));
        self.shared.retire(Garbage::QueryPool(self.profiler.pool));
        self.shared.retire(Garbage::Fence(self.fence));
        self.profiler.pool = vk::QueryPool::null();
        self.shared.end_recording(self.index);
    }
}

impl Drop for Submission {
    fn drop(&mut self) {
        if !self.waited {
            // SAFETY: the fence was submitted; waiting keeps the recording's objects alive until
            // the GPU is done with them.
            let r = unsafe {
                self.shared
                    .device
                    .wait_for_fences(&[self.fence], true, u64::MAX)
            };
            if let Err(e) = r {
                log::error!("waiting for an unwaited submission: {e:?}");
            }
            self.release();
        }
    }
}
