//! GPU timestamp profiling: every pass is one named scope with a timestamp pair and a debug label.
//!
//! A recording owns a timestamp query pool (reset at the start of the command buffer). Results are
//! read after the submission's fence, masked to `timestampValidBits`, subtracted with wrapping
//! arithmetic and scaled by `timestampPeriod`.

use ash::vk;

use crate::context::DeviceShared;
use crate::error::{Result, VkResultExt};

/// Timestamps per recording (two per scope).
pub(crate) const MAX_QUERIES: u32 = 512;

/// The measured time of one pass.
#[derive(Debug, Clone, PartialEq)]
pub struct PassTiming {
    /// Scope name (same as the debug label and the pass name).
    pub name: String,
    /// Nesting depth (0 for top-level passes).
    pub depth: u32,
    /// Start, in milliseconds after the recording's first timestamp.
    pub start_ms: f64,
    /// Duration in milliseconds.
    pub duration_ms: f64,
}

#[derive(Debug)]
pub(crate) struct Scope {
    pub name: String,
    pub depth: u32,
    pub begin: Option<u32>,
    pub end: Option<u32>,
}

/// Scopes and queries of one recording.
#[derive(Debug)]
pub(crate) struct ProfilerRecording {
    pub pool: vk::QueryPool,
    pub next_query: u32,
    pub scopes: Vec<Scope>,
    pub stack: Vec<usize>,
    pub overflow_warned: bool,
}

impl ProfilerRecording {
    pub(crate) fn new(shared: &DeviceShared) -> Result<Self> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(MAX_QUERIES);
        // SAFETY: the device is live; `info` is valid for the call.
        let pool =
            unsafe { shared.device.create_query_pool(&info, None) }.call("vkCreateQueryPool")?;
        Ok(ProfilerRecording {
            pool,
            next_query: 0,
            scopes: Vec::new(),
            stack: Vec::new(),
            overflow_warned: false,
        })
    }

    /// Takes the next query index, if any is left.
    pub(crate) fn take_query(&mut self) -> Option<u32> {
        if self.next_query < MAX_QUERIES {
            self.next_query += 1;
            Some(self.next_query - 1)
        } else {
            if !self.overflow_warned {
                log::warn!(
                    "more than {} pass scopes in one submission: later ones are not timed",
                    MAX_QUERIES / 2
                );
                self.overflow_warned = true;
            }
            None
        }
    }

    /// The name of the innermost open scope, or the last one opened.
    pub(crate) fn current_name(&self) -> Option<String> {
        self.stack
            .last()
            .or(self.scopes.len().checked_sub(1).as_ref())
            .and_then(|&i| self.scopes.get(i))
            .map(|s| s.name.clone())
    }

    /// Reads the timestamps (after the fence) and returns one timing per scope, in record order.
    pub(crate) fn resolve(&self, shared: &DeviceShared) -> Result<Vec<PassTiming>> {
        if self.next_query == 0 {
            return Ok(self.scopes.iter().map(untimed).collect());
        }
        let mut raw = vec![0u64; self.next_query as usize];
        // SAFETY: queries 0..next_query were reset and written by the completed submission.
        unsafe {
            shared.device.get_query_pool_results(
                self.pool,
                0,
                &mut raw,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .call("vkGetQueryPoolResults")?;
        let bits = shared.info.timestamp_valid_bits;
        let mask = if bits >= 64 {
            u64::MAX
        } else {
            (1u64 << bits) - 1
        };
        let period = shared.info.timestamp_period_ns;
        let origin = raw[0] & mask;
        let ms = |ticks: u64| (ticks & mask) as f64 * period * 1e-6;
        Ok(self
            .scopes
            .iter()
            .map(|s| match (s.begin, s.end) {
                (Some(b), Some(e)) => {
                    let (tb, te) = (raw[b as usize] & mask, raw[e as usize] & mask);
                    PassTiming {
                        name: s.name.clone(),
                        depth: s.depth,
                        start_ms: ms(tb.wrapping_sub(origin)),
                        duration_ms: ms(te.wrapping_sub(tb)),
                    }
                }
                _ => untimed(s),
            })
            .collect())
    }
}

fn untimed(s: &Scope) -> PassTiming {
    PassTiming {
        name: s.name.clone(),
        depth: s.depth,
        start_ms: 0.0,
        duration_ms: 0.0,
    }
}
