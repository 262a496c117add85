//! A cache's records in and out of an [`IcRenderer`] (cache files, `radcache_cache::cache_file`):
//! the records with their temporal states, last-use marks, radiance blocks (where the renderer
//! has radiance records) and the renderer's frame count, so a fresh renderer continues where the
//! exporting one stopped. Imported records take the path of
//! the records kept across a camera move: the next frame re-clamps their radii to its view
//! (whatever the view they were made for) and fills only the holes they leave.

use radcache_cache::cache_file::CacheRecords;
use radcache_vk::{Context, ShaderCompiler};

use super::{IcRenderer, Temporal};
use crate::error::{Error, Result};
use crate::passes::temporal::{NoLifespans, TemporalPass, TemporalVariant};
use crate::scene::GpuScene;

impl IcRenderer {
    /// The records left by the last frame (none before a frame or after [`Self::forget`]).
    pub fn export_cache(&self, ctx: &Context) -> Result<CacheRecords> {
        let lifespans = self.temporal.as_ref().is_some_and(Temporal::lifespans);
        if !self.has_records {
            return Ok(CacheRecords {
                frames: self.frames,
                lifespans,
                sky: self.sky_in_records,
                ..CacheRecords::default()
            });
        }
        let (records, temporal, last_used) = self.state.download(ctx)?;
        // Blocks that are not the records' own (imported without them) are not exported.
        let radiance = if self.glossy.is_some() && self.glossy_valid {
            self.state.download_radiance(ctx)?
        } else {
            Vec::new()
        };
        Ok(CacheRecords {
            records,
            temporal,
            last_used,
            frames: self.frames,
            lifespans,
            sky: self.sky_in_records,
            radiance,
        })
    }

    /// Replaces the renderer's records by `cache` (checked against the scene and parameters by
    /// the caller, e.g. `CacheHeader::check`): the next frame keeps them as the records of a
    /// previous frame, re-clamps them to its view and fills only the holes. Records with
    /// lifespans need a renderer made with a time step, records without one without. Marks
    /// later than the cache's frame count (impossible in a file this renderer wrote) count as
    /// made at that frame. The records' radiance blocks are uploaded where the renderer has
    /// radiance records (and ignored where it has none); without them glossy lobes go back to
    /// per-pixel paths until the records are made again.
    pub fn import_cache(
        &mut self,
        ctx: &Context,
        shaders: &ShaderCompiler,
        gpu: &GpuScene,
        cache: &CacheRecords,
    ) -> Result<()> {
        let lifespans = self.temporal.as_ref().is_some_and(Temporal::lifespans);
        if cache.lifespans != lifespans {
            return Err(Error::Invalid(format!(
                "the cache's records {} lifespans, the renderer's {}",
                if cache.lifespans { "carry" } else { "carry no" },
                if lifespans { "need them" } else { "have none" }
            )));
        }
        if cache.sky != self.sky_in_records {
            return Err(Error::Invalid(format!(
                "the cache's records {} the sky's light, the renderer's {} (`--set sky={}`)",
                if cache.sky { "hold" } else { "do not hold" },
                if self.sky_in_records {
                    "must"
                } else {
                    "must not"
                },
                if cache.sky { "records" } else { "direct" }
            )));
        }
        let n = cache.records.len();
        if !cache.radiance.is_empty() && cache.radiance.len() != n {
            return Err(Error::Invalid(format!(
                "the cache has {n} records but {} radiance blocks",
                cache.radiance.len()
            )));
        }
        let radiance = self.glossy.is_some();
        if self.temporal.is_none() {
            let variant = TemporalVariant {
                record_capacity: self.state.record_capacity(),
                lifespans: NoLifespans,
                radiance,
            };
            self.temporal = Some(Temporal::Kept(TemporalPass::new(
                ctx, shaders, gpu, &variant,
            )?));
        }
        let marks: Vec<u32> = cache
            .last_used
            .iter()
            .map(|&u| u.min(cache.frames))
            .collect();
        self.state
            .upload(ctx, &cache.records, &cache.temporal, &marks)?;
        let blocks = radiance && !cache.radiance.is_empty();
        if blocks {
            self.state.upload_radiance(ctx, &cache.radiance)?;
        }
        self.glossy_valid = blocks || n == 0;
        if let Some(t) = self.temporal.as_mut() {
            t.forget();
        }
        self.frames = cache.frames;
        self.has_records = !cache.records.is_empty();
        self.last_view = None;
        self.reclamp_next = true;
        Ok(())
    }
}
