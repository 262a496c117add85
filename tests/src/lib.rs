//! Harness for radcache's GPU tests: a validated lavapipe context, the shader compiler, and the
//! end-of-test check (no validation error, no leaked allocation).
//!
//! Tests run with the Khronos validation layer on (unless `RADCACHE_VALIDATION=0` is set by
//! hand); a missing layer fails the test instead of silently running unvalidated.

pub mod direct_cpu;
pub mod geometry;
pub mod ic_fixture;
pub mod record_fixture;
pub mod scenes;
pub mod shader_check;
pub mod sliding_box;
pub mod stiff;
pub mod twin;

use std::cell::RefCell;
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard, Once};

use radcache_vk::{Context, ContextOptions, ShaderCompiler};

static LOG: Once = Once::new();

/// Initialises logging once (`RUST_LOG` controls the level; warnings by default).
pub fn init_log() {
    LOG.call_once(|| {
        let _ = env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn"))
            .is_test(true)
            .try_init();
    });
}

/// The repository's `shaders/` folder.
pub fn shader_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shaders")
}

/// Whether validation was explicitly turned off for this run.
fn validation_disabled_by_user() -> bool {
    matches!(
        std::env::var("RADCACHE_VALIDATION").as_deref(),
        Ok("0") | Ok("false") | Ok("off") | Ok("no")
    )
}

/// The Vulkan contexts of one test process, one at a time (see [`context`]).
static ONE_CONTEXT_AT_A_TIME: Mutex<()> = Mutex::new(());

thread_local! {
    /// This test thread's turn, held until the thread ends (a test's last `finish` or panic).
    static TURN: RefCell<Option<MutexGuard<'static, ()>>> = const { RefCell::new(None) };
}

/// Waits until no other test thread of this process holds a Vulkan context, then keeps the
/// turn until this thread ends. Two lavapipe devices under the validation layer, created, used
/// and destroyed on two threads at once, crashed two CI runs out of many (glibc's heap check
/// `malloc_consolidate(): unaligned fastbin chunk`, and a C++ exception thrown through Rust
/// frames, both while one test shut its context down beside another's work). Neither
/// reproduced on a developer's machine and no fault in radcache's own Vulkan code was found; the
/// renderer itself creates one context per process, so the tests do the same: GPU tests of one binary run one after the other (lavapipe
/// already spreads each over every core), CPU-only tests still in parallel.
fn take_turn() {
    TURN.with(|turn| {
        let mut turn = turn.borrow_mut();
        if turn.is_none() {
            let guard = ONE_CONTEXT_AT_A_TIME
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner());
            *turn = Some(guard);
        }
    });
}

/// A context with validation on; panics with a clear message if the layer is missing. Contexts
/// of one test process are used one test at a time ([`take_turn`]).
pub fn context() -> Context {
    context_with(|_| {})
}

/// [`context`] with its options changed by `f` first.
pub fn context_with(f: impl FnOnce(&mut ContextOptions)) -> Context {
    take_turn();
    init_log();
    let mut opts = ContextOptions::from_env();
    opts.validation = !validation_disabled_by_user();
    // Tests leave the user's pipeline cache alone unless `RADCACHE_PIPELINE_CACHE` names one.
    if std::env::var_os(radcache_vk::PIPELINE_CACHE_ENV).is_none() {
        opts.pipeline_cache_dir = None;
    }
    f(&mut opts);
    let ctx =
        Context::with_options(&opts).unwrap_or_else(|e| panic!("creating the Vulkan context: {e}"));
    if opts.validation {
        assert!(
            ctx.info().validation,
            "the Khronos validation layer is not installed (apt-get install vulkan-validationlayers)"
        );
    }
    ctx
}

/// A shader compiler over the repository's shaders.
pub fn shaders() -> ShaderCompiler {
    ShaderCompiler::new(shader_root()).unwrap_or_else(|e| panic!("shader compiler: {e}"))
}

/// Shuts the context down and asserts no validation error occurred and nothing leaked.
pub fn finish(ctx: Context) {
    let first = ctx.first_validation_error();
    let report = ctx.shutdown();
    assert_eq!(
        report.validation_errors,
        0,
        "validation errors occurred; first: {}",
        first.unwrap_or_default()
    );
    assert!(
        report.leaked.is_empty(),
        "leaked GPU allocations: {:?}",
        report.leaked
    );
}

/// A small deterministic PRNG (splitmix64) for test inputs.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform float in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A uniform float in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }

    /// A uniform integer in [0, n).
    pub fn below(&mut self, n: u32) -> u32 {
        (self.next_u64() % u64::from(n.max(1))) as u32
    }
}
