//! The binding tables: the generated GLSL is current, no number is used twice, every table
//! fits the push descriptors.

use super::*;

#[test]
fn generated_glsl_is_up_to_date() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shaders/shared/bindings.glsl"
    );
    let on_disk = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        on_disk == generated_glsl(),
        "shaders/shared/bindings.glsl is stale: run `cargo xtask codegen`"
    );
}

#[test]
fn tables_number_their_bindings_once() {
    for table in [
        composite::layout(),
        direct::layout(),
        direct_composite_layout(),
        holes::layout(),
        record::layout(),
        splat::layout(),
        temporal::layout(),
        aov::layout(),
        emission::layout(),
        path_trace::layout(),
        neighbours::layout(),
        ic_counters::layout(),
    ] {
        let mut numbers: Vec<u32> = table.iter().map(|b| b.binding).collect();
        numbers.sort_unstable();
        let n = numbers.len();
        numbers.dedup();
        assert_eq!(
            numbers.len(),
            n,
            "a binding number is used twice: {table:?}"
        );
        // Push descriptors: Vulkan guarantees 32 a pipeline (lavapipe gives no more).
        assert!(
            n <= 32,
            "{n} bindings, more than 32 push descriptors: {table:?}"
        );
    }
    assert_eq!(composite::SPLAT_SUM, GBUFFER_END);
    assert_eq!(composite::SPLAT_COUNT, GBUFFER_END + 5);
    assert_eq!(temporal::MOVING, PASS_BASE + 7);
}
