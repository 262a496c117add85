//! Declaring GPU structs once, in Rust, and deriving their GLSL from it.
//!
//! `gpu_struct!` defines a `#[repr(C)]` `Pod` struct and records, per field, its GLSL type and its
//! Rust byte offset (`offset_of!`). [`std430_violations`] recomputes every offset with std430 rules
//! and reports any difference, so a struct whose Rust layout would not match GLSL fails a test, and
//! [`glsl_struct`] writes the GLSL declaration that `cargo xtask codegen` puts in
//! `shaders/shared/layouts.glsl`.

/// One field of a GPU struct.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    /// Field name (same in Rust and GLSL).
    pub name: &'static str,
    /// GLSL type (`float`, `uint`, `int`, `vec2`, `vec4`, `uvec4`, `ivec4`, `mat4`).
    pub glsl: &'static str,
    /// Byte offset in the Rust struct.
    pub offset: usize,
    /// Byte size in the Rust struct.
    pub size: usize,
    /// std430 (size, alignment) of the GLSL type, `None` for a type radcache does not support.
    pub std430: Option<(usize, usize)>,
}

/// A struct shared with GLSL.
pub trait GpuStruct: bytemuck::Pod {
    /// GLSL struct name.
    const NAME: &'static str;
    /// The fields in declaration order.
    fn fields() -> Vec<Field>;

    /// std430 (size, alignment) of the struct as a member of another one.
    fn std430() -> (usize, usize) {
        let mut offset = 0usize;
        let mut max_align = 4usize;
        for f in Self::fields() {
            let (size, align) = f.std430.unwrap_or((f.size, 4));
            max_align = max_align.max(align);
            offset = offset.div_ceil(align) * align + size;
        }
        (offset.div_ceil(max_align) * max_align, max_align)
    }
}

/// std430 (size, alignment) of a GLSL type radcache uses.
pub fn std430_size_align(glsl: &str) -> Option<(usize, usize)> {
    Some(match glsl {
        "float" | "uint" | "int" => (4, 4),
        "vec2" | "uvec2" | "ivec2" => (8, 8),
        "vec4" | "uvec4" | "ivec4" => (16, 16),
        "mat4" => (64, 16),
        _ => return None,
    })
}

/// Differences between the Rust layout of `T` and its std430 layout (empty when they agree).
pub fn std430_violations<T: GpuStruct>() -> Vec<String> {
    let mut errors = Vec::new();
    let mut offset = 0usize;
    let mut max_align = 4usize;
    for f in T::fields() {
        let Some((size, align)) = f.std430 else {
            errors.push(format!(
                "{}.{}: unsupported GLSL type {}",
                T::NAME,
                f.name,
                f.glsl
            ));
            continue;
        };
        max_align = max_align.max(align);
        offset = offset.div_ceil(align) * align;
        if offset != f.offset || size != f.size {
            errors.push(format!(
                "{}.{}: Rust offset {} size {}, std430 offset {offset} size {size}",
                T::NAME,
                f.name,
                f.offset,
                f.size
            ));
        }
        offset += size;
    }
    let std_size = offset.div_ceil(max_align) * max_align;
    if std_size != std::mem::size_of::<T>() {
        errors.push(format!(
            "{}: Rust size {}, std430 array stride {std_size}",
            T::NAME,
            std::mem::size_of::<T>()
        ));
    }
    errors
}

/// The GLSL declaration of `T`.
pub fn glsl_struct<T: GpuStruct>() -> String {
    let mut s = format!("struct {} {{\n", T::NAME);
    for f in T::fields() {
        s.push_str(&format!("    {} {};\n", f.glsl, f.name));
    }
    s.push_str(&format!("}};  // {} bytes\n", std::mem::size_of::<T>()));
    s
}

/// The GLSL type name and std430 (size, alignment) of a field declared `=> "glsl"` or
/// `=> struct` (a nested [`GpuStruct`]).
#[doc(hidden)]
#[macro_export]
macro_rules! __gpu_field_type {
    ($ty:ty, struct) => {
        (
            <$ty as $crate::layout::GpuStruct>::NAME,
            Some(<$ty as $crate::layout::GpuStruct>::std430()),
        )
    };
    ($ty:ty, $glsl:literal) => {
        ($glsl, $crate::layout::std430_size_align($glsl))
    };
}

/// Defines a `#[repr(C)]` plain-data struct shared with GLSL and its [`GpuStruct`] description.
/// Each field names its GLSL type (`=> "vec4"`), or `=> struct` for a nested shared struct.
#[macro_export]
macro_rules! gpu_struct {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $( $(#[$fmeta:meta])* pub $field:ident : $ty:ty => $glsl:tt ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        pub struct $name {
            $( $(#[$fmeta])* pub $field: $ty ),*
        }

        impl $crate::layout::GpuStruct for $name {
            const NAME: &'static str = stringify!($name);
            fn fields() -> Vec<$crate::layout::Field> {
                vec![$({
                    let (glsl, std430) = $crate::__gpu_field_type!($ty, $glsl);
                    $crate::layout::Field {
                        name: stringify!($field),
                        glsl,
                        offset: std::mem::offset_of!($name, $field),
                        size: std::mem::size_of::<$ty>(),
                        std430,
                    }
                }),*]
            }
        }
    };
}
