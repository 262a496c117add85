//! The resources a SPIR-V module uses, read from its instructions, so that pipeline creation can
//! check the binding table against the shader instead of trusting it.
//!
//! Vulkan requires the pipeline layout to declare every resource a shader statically uses, with
//! the right descriptor type and enough descriptors. From SPIR-V 1.4 on, an entry point's
//! interface lists every global variable it uses, so the used resources are the interface's
//! variables that carry a `Binding` decoration; older modules fall back to every decorated
//! variable. Only what the check needs is parsed: the variables, their pointer and base types,
//! the decorations `Binding`, `DescriptorSet`, `Block`, `BufferBlock` and `ArrayStride`, and the
//! member offsets and matrix strides that give the byte span of a push-constant block.

use std::collections::{HashMap, HashSet};

use crate::error::{Error, Result};
use crate::pipeline::{BindingKind, BindingLayout};

// Opcodes, storage classes and decorations of the SPIR-V specification.
const OP_ENTRY_POINT: u32 = 15;
const OP_TYPE_INT: u32 = 21;
const OP_TYPE_FLOAT: u32 = 22;
const OP_TYPE_VECTOR: u32 = 23;
const OP_TYPE_MATRIX: u32 = 24;
const OP_TYPE_IMAGE: u32 = 25;
const OP_TYPE_SAMPLER: u32 = 26;
const OP_TYPE_SAMPLED_IMAGE: u32 = 27;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
const OP_TYPE_STRUCT: u32 = 30;
const OP_TYPE_POINTER: u32 = 32;
const OP_CONSTANT: u32 = 43;
const OP_VARIABLE: u32 = 59;
const OP_DECORATE: u32 = 71;
const OP_MEMBER_DECORATE: u32 = 72;
const OP_TYPE_ACCELERATION_STRUCTURE: u32 = 5341;
const SC_UNIFORM_CONSTANT: u32 = 0;
const SC_UNIFORM: u32 = 2;
const SC_PUSH_CONSTANT: u32 = 9;
const SC_STORAGE_BUFFER: u32 = 12;
const DEC_BLOCK: u32 = 2;
const DEC_BUFFER_BLOCK: u32 = 3;
const DEC_ARRAY_STRIDE: u32 = 6;
const DEC_MATRIX_STRIDE: u32 = 7;
const DEC_OFFSET: u32 = 35;
const DEC_BINDING: u32 = 33;
const DEC_DESCRIPTOR_SET: u32 = 34;
const DEC_NON_WRITABLE: u32 = 24;

/// A type, as far as the check needs it.
#[derive(Debug, Clone)]
enum Type {
    /// `OpTypeImage` with its `Sampled` operand (1: sampled, 2: storage).
    Image(u32),
    Sampler,
    SampledImage,
    /// Element type and the id of the length constant.
    Array(u32, u32),
    RuntimeArray(u32),
    /// Member types.
    Struct(Vec<u32>),
    /// A scalar of this many bytes.
    Scalar(u64),
    /// Component type and count (a vector's components, a matrix's columns).
    Vector(u32, u32),
    Matrix(u32, u32),
    AccelerationStructure,
    /// The pointee (the variable's storage class decides the kind).
    Pointer(u32),
}

/// A resource the shader uses: (set, binding) → (kind, array length if known, whether the shader
/// may write it), or its complaint.
type Used = Vec<(
    u32,
    u32,
    std::result::Result<(BindingKind, Option<u32>, bool), String>,
)>;

/// What a module uses: its descriptor resources and, when it reads push constants, the byte
/// span of their block (`None` inside when it cannot be worked out).
struct Uses {
    resources: Used,
    push_constants: Option<Option<u64>>,
}

/// The layout decorations that give a block's byte span.
#[derive(Default)]
struct Layout {
    /// (struct, member) → byte offset / matrix stride.
    offsets: HashMap<(u32, u32), u64>,
    matrix_strides: HashMap<(u32, u32), u64>,
    array_strides: HashMap<u32, u64>,
}

impl Layout {
    /// The bytes from the start of a `ty` to the end of its last byte, if known; `matrix_stride`
    /// is the stride of the member this type is (for matrices).
    fn span(
        &self,
        types: &HashMap<u32, Type>,
        constants: &HashMap<u32, u32>,
        ty: u32,
        matrix_stride: Option<u64>,
        depth: u32,
    ) -> Option<u64> {
        if depth > 16 {
            return None;
        }
        let span = |t, stride| self.span(types, constants, t, stride, depth + 1);
        match types.get(&ty)? {
            Type::Scalar(bytes) => Some(*bytes),
            Type::Vector(c, n) => Some(span(*c, None)? * u64::from(*n)),
            Type::Matrix(column, n) => {
                let stride = matrix_stride?;
                Some(stride * u64::from(n.checked_sub(1)?) + span(*column, None)?)
            }
            Type::Array(elem, len) => {
                let len = u64::from(*constants.get(len)?);
                let stride = *self.array_strides.get(&ty)?;
                Some(stride * len.checked_sub(1)? + span(*elem, matrix_stride)?)
            }
            Type::Struct(members) => members.iter().enumerate().try_fold(0, |end, (i, m)| {
                let key = (ty, i as u32);
                let offset = *self.offsets.get(&key)?;
                Some(end.max(offset + span(*m, self.matrix_strides.get(&key).copied())?))
            }),
            _ => None,
        }
    }
}

fn literal_string_words(words: &[u32]) -> usize {
    words
        .iter()
        .position(|w| w.to_le_bytes().contains(&0))
        .map_or(words.len(), |i| i + 1)
}

fn parse(spirv: &[u32]) -> std::result::Result<Uses, String> {
    if spirv.len() < 5 || spirv[0] != crate::pipeline::SPIRV_MAGIC {
        return Err("not a SPIR-V module (no SPIR-V header)".into());
    }
    let version = spirv.get(1).copied().unwrap_or(0);
    let interface_lists_all = version >= 0x0001_0400;
    let mut types: HashMap<u32, Type> = HashMap::new();
    let mut constants: HashMap<u32, u32> = HashMap::new();
    let mut variables: Vec<(u32, u32, u32)> = Vec::new(); // (id, pointer type, storage class)
    let mut bindings: HashMap<u32, u32> = HashMap::new();
    let mut sets: HashMap<u32, u32> = HashMap::new();
    let mut blocks: HashSet<u32> = HashSet::new();
    let mut buffer_blocks: HashSet<u32> = HashSet::new();
    let mut interface: HashSet<u32> = HashSet::new();
    // Ids decorated NonWritable, and (struct, member) pairs member-decorated so (`readonly`).
    let mut non_writable: HashSet<u32> = HashSet::new();
    let mut non_writable_members: HashSet<(u32, u32)> = HashSet::new();
    let mut layout = Layout::default();
    let mut at = 5;
    while at < spirv.len() {
        let count = (spirv[at] >> 16) as usize;
        let op = spirv[at] & 0xffff;
        if count == 0 || at + count > spirv.len() {
            return Err(format!("malformed instruction at word {at}"));
        }
        let w = &spirv[at + 1..at + count];
        match op {
            OP_ENTRY_POINT if w.len() >= 2 => {
                let skip = 2 + literal_string_words(&w[2..]);
                interface.extend(w.iter().skip(skip));
            }
            OP_DECORATE if w.len() >= 2 => match (w[1], w.get(2)) {
                (DEC_BINDING, Some(&b)) => {
                    bindings.insert(w[0], b);
                }
                (DEC_DESCRIPTOR_SET, Some(&s)) => {
                    sets.insert(w[0], s);
                }
                (DEC_BLOCK, _) => {
                    blocks.insert(w[0]);
                }
                (DEC_BUFFER_BLOCK, _) => {
                    buffer_blocks.insert(w[0]);
                }
                (DEC_NON_WRITABLE, _) => {
                    non_writable.insert(w[0]);
                }
                (DEC_ARRAY_STRIDE, Some(&stride)) => {
                    layout.array_strides.insert(w[0], u64::from(stride));
                }
                _ => {}
            },
            OP_MEMBER_DECORATE if w.len() >= 3 && w[2] == DEC_NON_WRITABLE => {
                non_writable_members.insert((w[0], w[1]));
            }
            OP_MEMBER_DECORATE if w.len() >= 4 => match w[2] {
                DEC_OFFSET => {
                    layout.offsets.insert((w[0], w[1]), u64::from(w[3]));
                }
                DEC_MATRIX_STRIDE => {
                    layout.matrix_strides.insert((w[0], w[1]), u64::from(w[3]));
                }
                _ => {}
            },
            OP_TYPE_INT | OP_TYPE_FLOAT if w.len() >= 2 => {
                types.insert(w[0], Type::Scalar(u64::from(w[1] / 8)));
            }
            OP_TYPE_VECTOR if w.len() >= 3 => {
                types.insert(w[0], Type::Vector(w[1], w[2]));
            }
            OP_TYPE_MATRIX if w.len() >= 3 => {
                types.insert(w[0], Type::Matrix(w[1], w[2]));
            }
            OP_TYPE_IMAGE if w.len() >= 7 => {
                types.insert(w[0], Type::Image(w[6]));
            }
            OP_TYPE_SAMPLER if !w.is_empty() => {
                types.insert(w[0], Type::Sampler);
            }
            OP_TYPE_SAMPLED_IMAGE if !w.is_empty() => {
                types.insert(w[0], Type::SampledImage);
            }
            OP_TYPE_ARRAY if w.len() >= 3 => {
                types.insert(w[0], Type::Array(w[1], w[2]));
            }
            OP_TYPE_RUNTIME_ARRAY if w.len() >= 2 => {
                types.insert(w[0], Type::RuntimeArray(w[1]));
            }
            OP_TYPE_STRUCT if !w.is_empty() => {
                types.insert(w[0], Type::Struct(w[1..].to_vec()));
            }
            OP_TYPE_ACCELERATION_STRUCTURE if !w.is_empty() => {
                types.insert(w[0], Type::AccelerationStructure);
            }
            OP_TYPE_POINTER if w.len() >= 3 => {
                types.insert(w[0], Type::Pointer(w[2]));
            }
            OP_CONSTANT if w.len() >= 3 => {
                constants.insert(w[1], w[2]);
            }
            OP_VARIABLE if w.len() >= 3 => variables.push((w[1], w[0], w[2])),
            _ => {}
        }
        at += count;
    }
    let used = |id: &u32| !interface_lists_all || interface.contains(id);
    let push_constants = variables
        .iter()
        .find(|(id, _, class)| *class == SC_PUSH_CONSTANT && used(id))
        .map(|(_, pointer, _)| match types.get(pointer) {
            Some(Type::Pointer(block)) => layout.span(&types, &constants, *block, None, 0),
            _ => None,
        });
    let mut resources = Vec::new();
    for (id, pointer, class) in &variables {
        let Some(&binding) = bindings.get(id) else {
            continue;
        };
        if !used(id) {
            continue;
        }
        let set = sets.get(id).copied().unwrap_or(0);
        let pointee = match types.get(pointer) {
            Some(Type::Pointer(t)) => *t,
            _ => return Err(format!("variable %{id} is not a pointer")),
        };
        // Unwrap arrays: the element type decides the kind, the length the count.
        let (mut base, mut length) = (pointee, Some(1));
        loop {
            match types.get(&base) {
                Some(Type::Array(elem, len)) => {
                    length = constants.get(len).copied();
                    base = *elem;
                }
                Some(Type::RuntimeArray(elem)) => {
                    length = None;
                    base = *elem;
                }
                _ => break,
            }
        }
        let kind = match (*class, types.get(&base)) {
            (SC_STORAGE_BUFFER, _) => Ok(BindingKind::StorageBuffer),
            (SC_UNIFORM, _) if buffer_blocks.contains(&base) => Ok(BindingKind::StorageBuffer),
            (SC_UNIFORM, _) if blocks.contains(&base) => Ok(BindingKind::UniformBuffer),
            (SC_UNIFORM_CONSTANT, Some(Type::Image(2))) => Ok(BindingKind::StorageImage),
            (SC_UNIFORM_CONSTANT, Some(Type::SampledImage)) => Ok(BindingKind::SampledImage),
            (SC_UNIFORM_CONSTANT, Some(Type::AccelerationStructure)) => {
                Ok(BindingKind::AccelerationStructure)
            }
            (_, t) => Err(format!(
                "a resource radcache has no binding kind for (storage class {class}, {t:?})"
            )),
        };
        // A buffer is read-only when the variable or every member of its block is NonWritable
        // (glslang puts `readonly` on the members), an image when the variable is.
        let read_only = non_writable.contains(id)
            || match types.get(&base) {
                Some(Type::Struct(members)) => {
                    !members.is_empty()
                        && (0..members.len() as u32)
                            .all(|m| non_writable_members.contains(&(base, m)))
                }
                _ => false,
            };
        let writes = |k: BindingKind| {
            matches!(k, BindingKind::StorageBuffer | BindingKind::StorageImage) && !read_only
        };
        resources.push((set, binding, kind.map(|k| (k, length, writes(k)))));
    }
    Ok(Uses {
        resources,
        push_constants,
    })
}

/// Checks that `bindings` (set 0) declares every resource the modules use, with its kind and
/// enough descriptors, and that push constants are declared when a module reads them. Returns the
/// bindings some module may write (storage buffers and images not declared `readonly`).
pub(crate) fn check_layout(
    pipeline: &str,
    modules: &[&[u32]],
    bindings: &[BindingLayout],
    push_constant_size: u32,
) -> Result<Vec<u32>> {
    let mut written = Vec::new();
    let invalid = |m: String| Error::Invalid(format!("pipeline {pipeline:?}: {m}"));
    for spirv in modules {
        let uses = parse(spirv).map_err(|m| invalid(format!("cannot read its SPIR-V: {m}")))?;
        match uses.push_constants {
            Some(_) if push_constant_size == 0 => {
                return Err(invalid(
                    "the shader reads push constants, the pipeline declares none".into(),
                ))
            }
            Some(None) => {
                return Err(invalid(
                    "cannot work out the byte span of the shader's push-constant block".into(),
                ))
            }
            Some(Some(span)) if span > u64::from(push_constant_size) => {
                return Err(invalid(format!(
                    "the shader's push-constant block spans {span} bytes, the pipeline declares \
                     {push_constant_size}"
                )))
            }
            _ => {}
        }
        for (set, binding, used) in uses.resources {
            let (kind, length, writes) =
                used.map_err(|m| invalid(format!("binding {binding}: {m}")))?;
            if writes && !written.contains(&binding) {
                written.push(binding);
            }
            if set != 0 {
                return Err(invalid(format!(
                    "the shader uses set {set} (binding {binding}); radcache pipelines have set 0 only"
                )));
            }
            let declared = bindings
                .iter()
                .find(|b| b.binding == binding)
                .ok_or_else(|| {
                    invalid(format!(
                        "the shader uses binding {binding} ({kind:?}), which its binding table \
                         does not declare"
                    ))
                })?;
            if declared.kind != kind {
                return Err(invalid(format!(
                    "binding {binding} is declared {:?}, the shader uses it as {kind:?}",
                    declared.kind
                )));
            }
            if let Some(n) = length.filter(|n| *n > declared.count) {
                return Err(invalid(format!(
                    "binding {binding} declares {} descriptors, the shader's array has {n}",
                    declared.count
                )));
            }
        }
    }
    Ok(written)
}
