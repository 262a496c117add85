//! Shared set-up of radcache-vk's GPU tests: a validated context (lavapipe in CI), the test
//! shaders, and the check that a misuse panics before it reaches Vulkan.
//!
//! Run with `RADCACHE_VALIDATION=1 VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.json`
//! (`cargo xtask test` sets both). Each test ends with [`finish`]: no validation error, nothing
//! leaked, which proves that every refused call was refused before Vulkan saw it.

#![allow(dead_code)] // each test file uses its own subset

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use bytemuck::{Pod, Zeroable};
use radcache_vk::{
    vk, BindingKind, BindingLayout, Blend, Buffer, BufferDesc, Context, ContextOptions,
    GraphicsDesc, Image, ImageDesc, MemoryLocation, Pipeline, ShaderCompiler,
};

/// A context with the validation layer on (unless `RADCACHE_VALIDATION=0`); panics if the layer
/// is missing, so a test never passes unvalidated by accident.
pub fn context() -> Context {
    let mut opts = ContextOptions::from_env();
    let off = matches!(
        std::env::var("RADCACHE_VALIDATION").as_deref(),
        Ok("0") | Ok("false") | Ok("off") | Ok("no")
    );
    opts.validation = !off;
    // Tests leave the user's pipeline cache alone unless `RADCACHE_PIPELINE_CACHE` names one.
    if std::env::var_os(radcache_vk::PIPELINE_CACHE_ENV).is_none() {
        opts.pipeline_cache_dir = None;
    }
    let ctx = Context::with_options(&opts).unwrap_or_else(|e| panic!("creating the context: {e}"));
    if opts.validation {
        assert!(
            ctx.info().validation,
            "the Khronos validation layer is not installed (apt-get install vulkan-validationlayers)"
        );
    }
    ctx
}

/// Shuts the context down; asserts no validation error occurred and nothing leaked.
pub fn finish(ctx: Context) {
    let first = ctx.first_validation_error();
    let report = ctx.shutdown();
    assert_eq!(
        report.validation_errors,
        0,
        "validation errors occurred; first: {}",
        first.unwrap_or_default()
    );
    assert!(report.leaked.is_empty(), "leaked: {:?}", report.leaked);
}

/// The compiler over `tests/shaders/`.
pub fn compiler() -> ShaderCompiler {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/shaders");
    ShaderCompiler::new(root).expect("shader compiler")
}

/// Runs `f`, which must panic with a message containing `expected`.
pub fn expect_panic(expected: &str, f: impl FnOnce()) {
    let err = catch_unwind(AssertUnwindSafe(f)).expect_err("the call should have panicked");
    let message = err
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| err.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_default();
    assert!(
        message.contains(expected),
        "panic message {message:?} lacks {expected:?}"
    );
}

/// `fill.comp`'s push constants.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct FillPush {
    pub value: u32,
    pub count: u32,
}

/// `fill.comp`: binding 0 the output, binding 1 the addend, push constants [`FillPush`].
pub fn fill_pipeline(ctx: &Context, compiler: &ShaderCompiler) -> Pipeline {
    let spirv = compiler.compile("fill.comp", &[]).expect("fill.comp");
    Pipeline::compute(
        ctx,
        "test.fill",
        &spirv,
        &[
            BindingLayout::new(0, BindingKind::StorageBuffer),
            BindingLayout::new(1, BindingKind::StorageBuffer),
        ],
        std::mem::size_of::<FillPush>() as u32,
    )
    .expect("fill pipeline")
}

/// `tri.vert` + `tri.frag` into one RGBA32F attachment; binding 0 the colour.
pub fn tri_pipeline(ctx: &Context, compiler: &ShaderCompiler) -> Pipeline {
    let vertex = compiler.compile("tri.vert", &[]).expect("tri.vert");
    let fragment = compiler.compile("tri.frag", &[]).expect("tri.frag");
    Pipeline::graphics(
        ctx,
        &GraphicsDesc {
            name: "test.tri",
            vertex: &vertex,
            fragment: &fragment,
            bindings: &[BindingLayout::new(0, BindingKind::StorageBuffer)],
            push_constant_size: 0,
            color_formats: &[vk::Format::R32G32B32A32_SFLOAT],
            depth: None,
            blend: Blend::None,
            cull: vk::CullModeFlags::NONE,
            topology: vk::PrimitiveTopology::TRIANGLE_LIST,
        },
    )
    .expect("tri pipeline")
}

/// A host-visible buffer of `words` u32s holding `fill`.
pub fn host_buffer(
    ctx: &Context,
    name: &str,
    usage: vk::BufferUsageFlags,
    words: &[u32],
) -> Buffer {
    let mut b = Buffer::new(
        ctx,
        &BufferDesc {
            name,
            size: (words.len() * 4) as u64,
            usage,
            location: MemoryLocation::CpuToGpu,
            alignment: 0,
        },
    )
    .expect("buffer");
    b.write(0, words).expect("initial write");
    b
}

/// An RGBA32F image usable as colour attachment and storage image.
pub fn colour_image(ctx: &Context, name: &str, size: u32) -> Image {
    Image::new(
        ctx,
        &ImageDesc {
            name,
            width: size,
            height: size,
            format: vk::Format::R32G32B32A32_SFLOAT,
            usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::STORAGE,
        },
    )
    .expect("image")
}
