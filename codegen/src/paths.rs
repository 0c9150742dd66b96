//! The primitive types and prelude items the emitted code (and `scene!`'s) names, each by its
//! full path (`::core::primitive::f64`, `::core::option::Option::Some`): the generated items
//! land in the caller's module, where a generated type, or anything else, may be called `f64`,
//! `usize`, `str`, `Option`, `Some` or `None` and would otherwise change what the code means.

use proc_macro2::TokenStream;
use quote::{format_ident, quote, ToTokens};

/// `::core::primitive::NAME`: the primitive type `name` (`f64`, `usize`, `u64`, `str`, …).
#[must_use]
pub fn primitive(name: &str) -> TokenStream {
    let name = format_ident!("{name}");
    quote!(::core::primitive::#name)
}

/// `&'static str`, by the full path of `str`.
#[must_use]
pub fn static_str() -> TokenStream {
    let s = primitive("str");
    quote!(&'static #s)
}

/// `Option<T>`, by its full path.
#[must_use]
pub fn option_type(t: &TokenStream) -> TokenStream {
    quote!(::core::option::Option<#t>)
}

/// `Some(x)` or `None`, by their full paths.
#[must_use]
pub fn option<T: ToTokens>(x: Option<T>) -> TokenStream {
    match x {
        Some(x) => quote!(::core::option::Option::Some(#x)),
        None => quote!(::core::option::Option::None),
    }
}

/// `Result<T, E>`, by its full path.
#[must_use]
pub fn result_type(t: &TokenStream, e: &TokenStream) -> TokenStream {
    quote!(::core::result::Result<#t, #e>)
}

/// `Ok(x)`, by its full path (an expression or a pattern).
#[must_use]
pub fn ok<T: ToTokens>(x: T) -> TokenStream {
    quote!(::core::result::Result::Ok(#x))
}

/// `Err(x)`, by its full path (an expression or a pattern).
#[must_use]
pub fn err<T: ToTokens>(x: T) -> TokenStream {
    quote!(::core::result::Result::Err(#x))
}

/// Names the including module may give another meaning: the primitive types, the prelude's
/// items (the traits among them name a bound such as `impl FnMut(…)`; a method call finds a
/// prelude trait whatever the module calls its name), the built-in macros the emitted code
/// calls and the standard crates.
pub const SHADOWABLE: &[&str] = &[
    "bool",
    "char",
    "str",
    "f32",
    "f64",
    "i8",
    "i16",
    "i32",
    "i64",
    "i128",
    "isize",
    "u8",
    "u16",
    "u32",
    "u64",
    "u128",
    "usize",
    "Option",
    "Some",
    "None",
    "Result",
    "Ok",
    "Err",
    "Box",
    "String",
    "Vec",
    "Default",
    "Clone",
    "Copy",
    "Iterator",
    "IntoIterator",
    "Into",
    "From",
    "TryFrom",
    "TryInto",
    "Fn",
    "FnMut",
    "FnOnce",
    "include_bytes",
    "core",
    "std",
    "alloc",
];

/// The paths of `items` (every path: types, expressions, patterns, bounds, macro calls) that
/// start with a [`SHADOWABLE`] name and no leading `::`, as text: none, when the code means the
/// same in any module.
///
/// # Errors
/// The parse error when `items` are not Rust items.
pub fn unqualified(items: TokenStream) -> syn::Result<Vec<String>> {
    use syn::visit::Visit;
    #[derive(Default)]
    struct Unqualified(Vec<String>);
    impl<'a> Visit<'a> for Unqualified {
        fn visit_path(&mut self, p: &'a syn::Path) {
            let first = p.segments.first().map(|s| s.ident.to_string());
            if let (None, Some(first)) = (&p.leading_colon, first) {
                if SHADOWABLE.contains(&first.as_str()) {
                    self.0.push(quote!(#p).to_string());
                }
            }
            syn::visit::visit_path(self, p);
        }
    }
    let file: syn::File = syn::parse2(items)?;
    let mut v = Unqualified::default();
    v.visit_file(&file);
    Ok(v.0)
}

#[cfg(test)]
mod tests {
    use crate::{generate_items, Float, Form, Options};
    use kanegen_model::random::{random_chain, ChainSpec};
    use kanegen_model::BaseKind;

    /// Every variant of the emitted code (straight-line and compact, fixed and free-floating,
    /// `f64` and `f32`, a runtime payload, gravity, the fused and the table helpers) names every
    /// primitive type and prelude item by its full path.
    #[test]
    fn emitted_code_names_primitives_and_prelude_items_by_full_paths() {
        let chain = random_chain(
            &ChainSpec {
                n: 3,
                prismatic_fraction: 0.3,
                ..Default::default()
            },
            2,
        );
        let ssrms = kanegen_model::io::load_model(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/ssrms.toml"),
        )
        .unwrap();
        let variants = [
            (&chain, None, Form::Unrolled, Float::F64, false),
            (&chain, None, Form::Unrolled, Float::F32, true),
            (&chain, None, Form::Compact, Float::F64, false),
            (
                &ssrms,
                Some(BaseKind::FreeFloating),
                Form::Compact,
                Float::F64,
                false,
            ),
            (
                &ssrms,
                Some(BaseKind::FreeFloating),
                Form::Unrolled,
                Float::F32,
                false,
            ),
        ];
        for (model, base, form, float, fma) in variants {
            let mut o = Options::new("Arm");
            o.gravity = Some([0.0, 0.0, -9.81]);
            o.runtime_payload = true;
            o.base = base;
            o.form = form;
            o.float = float;
            o.fma = fma;
            o.derivatives = false;
            let items = generate_items(model, &o).unwrap().items;
            let unqualified = super::unqualified(items).unwrap();
            assert!(
                unqualified.is_empty(),
                "{form:?} {float:?} {base:?}: {unqualified:?}"
            );
        }
    }
}
