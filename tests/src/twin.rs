//! The harness of the GLSL twin tests (`tests/tests/ircache_glsl.rs`, `tests/tests/brdf_glsl.rs`):
//! rows of inputs, their expected outputs and how each lane is compared, run through a twin shader
//! (`shaders/tests/ircache_twin.comp`, `shaders/tests/brdf_twin.comp`).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use radcache_vk::{vk, BindingKind, BindingLayout, Context, Pipeline, Resource};

use crate::Rng;
pub use radcache_shared::consts::{BrdfTwinMode, ShTwinMode, TwinMode};

/// The pipeline of the twin shader `shaders/tests/<file>`: its three storage buffers (inputs,
/// outputs, samples) and the 8-byte push block `{mode, count}`.
pub fn twin_pipeline(ctx: &Context, file: &str, name: &str) -> Pipeline {
    let spirv = crate::shaders()
        .compile(&format!("tests/{file}"), &[])
        .unwrap();
    let layout: Vec<BindingLayout> = (0..3)
        .map(|b| BindingLayout::new(b, BindingKind::StorageBuffer))
        .collect();
    Pipeline::compute(ctx, name, &spirv, &layout, 8).unwrap()
}

/// A twin shader's mode (its push constant `mode`).
pub trait ShaderMode: Copy {
    /// The value of the push constant.
    fn bits(self) -> u32;
}

impl ShaderMode for TwinMode {
    fn bits(self) -> u32 {
        self as u32
    }
}

impl ShaderMode for ShTwinMode {
    fn bits(self) -> u32 {
        self as u32
    }
}

impl ShaderMode for BrdfTwinMode {
    fn bits(self) -> u32 {
        self as u32
    }
}

/// The largest differences seen in one output lane of a family (compared lanes only).
#[derive(Clone, Copy, Debug, Default)]
pub struct LaneDiff {
    /// Largest `|gpu − cpu|`.
    pub abs: f32,
    /// Largest `|gpu − cpu| / |cpu|` over the values with `|cpu| >= 1e-6`.
    pub rel: f32,
    /// Largest fraction of the tolerance used: `|gpu − cpu| / (1e-5 · max(|cpu|, scale) + 1e-6)`.
    pub of_tolerance: f32,
}

/// 16 vec4 of inputs or outputs (uints as float bits, booleans as 0/1).
pub type Row = [[f32; 4]; 16];
/// A row of inputs and its expected outputs.
pub type Case = (Row, Expect);

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Push {
    mode: u32,
    count: u32,
}

/// How one output lane is compared.
#[derive(Clone, Copy, Debug)]
pub enum How {
    /// Not an output of this row.
    Unused,
    /// Within rounding of a step: not compared (counted; must stay rare).
    Tie,
    /// Bit for bit.
    Exact,
    /// Within the tolerance for terms of this size (see the test's header).
    Near(f32),
}

/// Expected outputs of one row.
#[derive(Clone, Copy, Debug)]
pub struct Expect {
    /// Expected values.
    pub v: Row,
    /// How each lane is compared.
    pub how: [[How; 4]; 16],
}

impl Default for Expect {
    fn default() -> Self {
        Self::new()
    }
}

impl Expect {
    /// Nothing compared yet.
    pub fn new() -> Self {
        Expect {
            v: [[0.0; 4]; 16],
            how: [[How::Unused; 4]; 16],
        }
    }

    /// Lane `lane` of slot `slot`, within the tolerance for terms of size `scale`.
    pub fn f(&mut self, slot: usize, lane: usize, x: f32, scale: f32) {
        self.v[slot][lane] = x;
        self.how[slot][lane] = How::Near(scale);
    }

    /// A whole slot of four values, like [`Expect::f`].
    pub fn s(&mut self, slot: usize, x: [f32; 4], scale: f32) {
        for (lane, x) in x.into_iter().enumerate() {
            self.f(slot, lane, x, scale);
        }
    }

    /// Three lanes of a slot, like [`Expect::f`].
    pub fn v(&mut self, slot: usize, x: Vec3, scale: f32) {
        for c in 0..3 {
            self.f(slot, c, x[c], scale);
        }
    }

    /// Lane `lane` of slot `slot`, bit for bit.
    pub fn exact(&mut self, slot: usize, lane: usize, x: f32) {
        self.v[slot][lane] = x;
        self.how[slot][lane] = How::Exact;
    }

    /// A boolean (0/1), or a tie when its CPU `margin` is non-zero but within `resolution`.
    pub fn b(&mut self, slot: usize, lane: usize, x: bool, margin: f32, resolution: f32) {
        self.exact(slot, lane, if x { 1.0 } else { 0.0 });
        if margin != 0.0 && margin.abs() <= resolution {
            self.how[slot][lane] = How::Tie;
        }
    }
}

/// `v` with `w`.
pub fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

/// A u32 carried as float bits.
pub fn ub(u: u32) -> f32 {
    f32::from_bits(u)
}

/// A random unit vector.
pub fn unit(rng: &mut Rng) -> Vec3 {
    loop {
        let v = vec(rng, 1.0);
        if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
            return v.normalize();
        }
    }
}

/// A random vector in `[−s, s]³`.
pub fn vec(rng: &mut Rng, s: f32) -> Vec3 {
    Vec3::new(rng.range(-s, s), rng.range(-s, s), rng.range(-s, s))
}

/// Runs one family through the twin shader in `mode` and compares every expected lane.
pub fn check(
    ctx: &Context,
    pl: &Pipeline,
    mode: impl ShaderMode,
    cases: &[Case],
    samples: &[[f32; 4]],
) {
    check_diffs(ctx, pl, mode, cases, samples);
}

/// [`check`], returning the largest differences per output lane (`[slot][lane]`).
pub fn check_diffs(
    ctx: &Context,
    pl: &Pipeline,
    mode: impl ShaderMode,
    cases: &[Case],
    samples: &[[f32; 4]],
) -> [[LaneDiff; 4]; 16] {
    let mode = mode.bits();
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let rows: Vec<Row> = cases.iter().map(|c| c.0).collect();
    let inputs = ctx.create_buffer_init("twin.in", storage, &rows).unwrap();
    let samples = [samples, &[[0.0; 4]]].concat();
    let samples = ctx.create_buffer_init("twin.s", storage, &samples).unwrap();
    let outputs = ctx.create_buffer_init("twin.out", storage, &rows).unwrap();
    let count = rows.len() as u32;
    let mut rec = ctx.begin("twin").unwrap();
    rec.pass("twin", |rec| {
        rec.bind_pipeline(pl);
        rec.push_bindings(&[
            (0, Resource::Buffer(&inputs)),
            (1, Resource::Buffer(&outputs)),
            (2, Resource::Buffer(&samples)),
        ]);
        rec.push_constants(&Push { mode, count });
        rec.dispatch(count.div_ceil(64), 1, 1)
    })
    .unwrap();
    ctx.submit(rec).unwrap().wait().unwrap();
    let out: Vec<Row> = ctx.read_buffer(&outputs, rows.len()).unwrap();
    let (mut failures, mut compared, mut ties) = (Vec::new(), 0usize, 0usize);
    let mut diffs = [[LaneDiff::default(); 4]; 16];
    for (r, ((_, e), o)) in cases.iter().zip(&out).enumerate() {
        for (slot, lane) in (0..16).flat_map(|s| (0..4).map(move |l| (s, l))) {
            let (gpu, cpu) = (o[slot][lane], e.v[slot][lane]);
            let ok = match e.how[slot][lane] {
                How::Unused => continue,
                How::Tie => {
                    ties += 1;
                    continue;
                }
                How::Exact => gpu.to_bits() == cpu.to_bits(),
                How::Near(s) => gpu == cpu || (gpu - cpu).abs() <= 1e-5 * cpu.abs().max(s) + 1e-6,
            };
            compared += 1;
            let d = &mut diffs[slot][lane];
            d.abs = d.abs.max((gpu - cpu).abs());
            if let How::Near(scale) = e.how[slot][lane] {
                let diff = (gpu - cpu).abs();
                if cpu.abs() >= 1e-6 {
                    d.rel = d.rel.max(diff / cpu.abs());
                }
                d.of_tolerance = d
                    .of_tolerance
                    .max(diff / (1e-5 * cpu.abs().max(scale) + 1e-6));
            }
            if !ok {
                let (how, at) = (e.how[slot][lane], format!("row {r} out[{slot}][{lane}]"));
                failures.push(format!("{at}: GPU {gpu:e}, CPU {cpu:e} ({how:?})"));
            }
        }
    }
    eprintln!("mode {mode}: {compared} values compared, {ties} ties skipped");
    assert!(compared > 0 && ties * 50 <= compared, "{ties} ties");
    let shown = failures[..failures.len().min(25)].join("\n");
    assert!(failures.is_empty(), "mode {mode}:\n{shown}");
    diffs
}
