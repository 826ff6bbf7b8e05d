//! `#[derive(Rules)]`: the one declaration of a request type's per-field rules.
//!
//! A rule is written once, as a `#[rule(...)]` attribute on the field it constrains:
//!
//! ```ignore
//! #[derive(Deserialize, ToSchema, Rules)]
//! #[rules(code = "BAD_RANGE", one_of("power_W", "input_torque_Nm"))]
//! pub struct Gear {
//!     /// Ring radius `r2` \[mm\].
//!     #[rule(range = R2_MM)]
//!     pub r2_mm: f64,
//!     /// Sample times \[s\].
//!     #[rule(items = TIME, min_items = 2, max_items = 10_000)]
//!     pub t_s: Vec<f64>,
//!     ...
//! }
//! ```
//!
//! The derive expands to an implementation of `crate::calc::rules::Rules` with two readers of
//! that one declaration: `check_rules`, which walks a decoded request and records every broken
//! rule with its JSON pointer (built from the wire names serde uses), its quantity, unit (the first
//! bracketed unit of the field's doc) and limit; and `document_rules`, which lists the same rules
//! as JSON Schema keywords for the OpenAPI document. Every field is visited, so nested request
//! types are checked without being named twice.
//!
//! It also enforces "null means absent": an optional field (serde `default`) whose type is not an
//! `Option` must say how it reads `null` (`deserialize_with`), else the derive fails to compile.

use proc_macro::TokenStream;
use proc_macro2::TokenStream as Ts;
use quote::{quote, quote_spanned};
use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::{
    Attribute, Data, DeriveInput, Expr, Fields, LitStr, Meta, Token, Type, parse_macro_input,
};

/// See the crate docs.
#[proc_macro_derive(Rules, attributes(rule, rules))]
pub fn derive_rules(input: TokenStream) -> TokenStream {
    let input = parse_macro_input!(input as DeriveInput);
    match expand(&input) {
        Ok(ts) => ts.into(),
        Err(e) => e.to_compile_error().into(),
    }
}

/// serde's container attributes that change wire names or the shape.
#[derive(Default)]
struct SerdeContainer {
    rename_all: Option<String>,
    tag: Option<String>,
    untagged: bool,
    default: bool,
}

/// serde's field attributes that matter here.
#[derive(Default)]
struct SerdeField {
    rename: Option<String>,
    default: bool,
    custom_de: bool,
    skip: bool,
}

/// The `#[rule(...)]` of one field or newtype variant.
#[derive(Default)]
struct FieldRules {
    range: Option<Expr>,
    items: Option<Expr>,
    items_items: Option<Expr>,
    values: Option<Expr>,
    min_len: Option<Expr>,
    max_len: Option<Expr>,
    code: Option<LitStr>,
}

impl FieldRules {
    fn is_empty(&self) -> bool {
        self.range.is_none()
            && self.items.is_none()
            && self.items_items.is_none()
            && self.values.is_none()
            && self.min_len.is_none()
            && self.max_len.is_none()
    }
}

/// The container's `#[rules(...)]`.
#[derive(Default)]
struct ContainerRules {
    code: Option<LitStr>,
    /// Groups of exactly-one fields, and whether a failure points at the object (else the field).
    one_of: Vec<(Vec<LitStr>, bool)>,
}

fn serde_metas(attrs: &[Attribute]) -> syn::Result<Vec<Meta>> {
    let mut out = Vec::new();
    for a in attrs.iter().filter(|a| a.path().is_ident("serde")) {
        let list = a.parse_args_with(Punctuated::<Meta, Token![,]>::parse_terminated)?;
        out.extend(list);
    }
    Ok(out)
}

fn lit_str_of(m: &Meta) -> Option<String> {
    if let Meta::NameValue(nv) = m
        && let Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Str(s),
            ..
        }) = &nv.value
    {
        return Some(s.value());
    }
    None
}

fn serde_container(attrs: &[Attribute]) -> syn::Result<SerdeContainer> {
    let mut c = SerdeContainer::default();
    for m in serde_metas(attrs)? {
        let p = m.path();
        if p.is_ident("rename_all") {
            c.rename_all = lit_str_of(&m);
        } else if p.is_ident("tag") {
            c.tag = lit_str_of(&m);
        } else if p.is_ident("untagged") {
            c.untagged = true;
        } else if p.is_ident("default") {
            c.default = true;
        }
    }
    Ok(c)
}

fn serde_field(attrs: &[Attribute]) -> syn::Result<SerdeField> {
    let mut f = SerdeField::default();
    for m in serde_metas(attrs)? {
        let p = m.path();
        if p.is_ident("rename") {
            f.rename = lit_str_of(&m);
        } else if p.is_ident("default") {
            f.default = true;
        } else if p.is_ident("deserialize_with") || p.is_ident("with") {
            f.custom_de = true;
        } else if p.is_ident("skip") || p.is_ident("skip_deserializing") {
            f.skip = true;
        }
    }
    Ok(f)
}

fn field_rules(attrs: &[Attribute]) -> syn::Result<FieldRules> {
    let mut r = FieldRules::default();
    for a in attrs.iter().filter(|a| a.path().is_ident("rule")) {
        a.parse_nested_meta(|m| {
            let key = m
                .path
                .get_ident()
                .map(ToString::to_string)
                .unwrap_or_default();
            match key.as_str() {
                "range" => r.range = Some(m.value()?.parse()?),
                "items" => r.items = Some(m.value()?.parse()?),
                "items_items" => r.items_items = Some(m.value()?.parse()?),
                "values" => r.values = Some(m.value()?.parse()?),
                "min_items" | "min_length" => r.min_len = Some(m.value()?.parse()?),
                "max_items" | "max_length" => r.max_len = Some(m.value()?.parse()?),
                "code" => r.code = Some(m.value()?.parse()?),
                _ => {
                    return Err(m.error(
                        "unknown rule: expected range, items, items_items, values, min_items, \
                         max_items, min_length, max_length or code",
                    ));
                }
            }
            Ok(())
        })?;
    }
    Ok(r)
}

fn container_rules(attrs: &[Attribute]) -> syn::Result<ContainerRules> {
    let mut r = ContainerRules::default();
    for a in attrs.iter().filter(|a| a.path().is_ident("rules")) {
        a.parse_nested_meta(|m| {
            if m.path.is_ident("code") {
                r.code = Some(m.value()?.parse()?);
                Ok(())
            } else if m.path.is_ident("one_of") || m.path.is_ident("one_of_object") {
                let content;
                syn::parenthesized!(content in m.input);
                let names = Punctuated::<LitStr, Token![,]>::parse_terminated(&content)?;
                r.one_of.push((
                    names.into_iter().collect(),
                    m.path.is_ident("one_of_object"),
                ));
                Ok(())
            } else {
                Err(m.error("unknown container rule: expected code or one_of(\"a\", \"b\", ...)"))
            }
        })?;
    }
    Ok(r)
}

/// serde's `rename_all` for the cases the wire types use.
fn rename(name: &str, rule: Option<&str>) -> String {
    match rule {
        Some("snake_case") => {
            let mut out = String::new();
            for (i, ch) in name.chars().enumerate() {
                if ch.is_uppercase() {
                    if i > 0 {
                        out.push('_');
                    }
                    out.extend(ch.to_lowercase());
                } else {
                    out.push(ch);
                }
            }
            out
        }
        Some("lowercase") => name.to_lowercase(),
        Some("UPPERCASE") => name.to_uppercase(),
        _ => name.to_owned(),
    }
}

/// The first unit in brackets in a doc comment (`\[m\]`, `[N·m]`; not a Markdown link).
fn unit_of(attrs: &[Attribute]) -> String {
    let mut doc = String::new();
    for a in attrs.iter().filter(|a| a.path().is_ident("doc")) {
        if let Meta::NameValue(nv) = &a.meta
            && let Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) = &nv.value
        {
            doc.push_str(&s.value());
            doc.push(' ');
        }
    }
    let doc = doc.replace("\\[", "[").replace("\\]", "]");
    let mut rest = doc.as_str();
    while let Some(open) = rest.find('[') {
        let after = &rest[open + 1..];
        let Some(close) = after.find(']') else { break };
        let inside = &after[..close];
        let next = after[close + 1..].chars().next();
        let link = matches!(next, Some('(' | '['));
        if !link && !inside.is_empty() && !inside.contains('`') && inside.len() <= 24 {
            return inside.to_owned();
        }
        rest = &after[close + 1..];
    }
    String::new()
}

fn is_option(ty: &Type) -> bool {
    if let Type::Path(p) = ty
        && let Some(seg) = p.path.segments.last()
    {
        return seg.ident == "Option";
    }
    false
}

/// One field to check: how to reach it, its wire name and JSON Schema location, its rules.
struct FieldSpec<'a> {
    access: Ts,
    wire: String,
    ty: &'a Type,
    unit: String,
    rules: FieldRules,
    /// JSON pointer inside the owning schema (`/properties/x`, `/oneOf/1/properties/x`, `/oneOf/0`).
    schema_ptr: String,
    span: proc_macro2::Span,
}

fn code_tokens(field: Option<&LitStr>, container: Option<&LitStr>) -> Ts {
    match field.or(container) {
        Some(c) => quote!(::core::option::Option::Some(#c)),
        None => quote!(::core::option::Option::None),
    }
}

/// The check of one field's rules and the recursion into its value.
fn check_field(f: &FieldSpec<'_>, container_code: Option<&LitStr>, at_key: bool) -> Ts {
    let access = &f.access;
    let wire = &f.wire;
    let unit = &f.unit;
    let code = code_tokens(f.rules.code.as_ref(), container_code);
    let at = if at_key {
        quote!(let __at = __at.key(#wire);)
    } else {
        quote!()
    };
    let mut body = Vec::new();
    if let Some(e) = &f.rules.range {
        body.push(
            quote_spanned!(e.span()=> crate::calc::rules::range(#access, &F, #e, __at, __v);),
        );
    }
    if let Some(e) = &f.rules.items {
        body.push(
            quote_spanned!(e.span()=> crate::calc::rules::items(#access, &F, #e, __at, __v);),
        );
    }
    if let Some(e) = &f.rules.items_items {
        body.push(
            quote_spanned!(e.span()=> crate::calc::rules::items_items(#access, &F, #e, __at, __v);),
        );
    }
    if let Some(e) = &f.rules.values {
        body.push(
            quote_spanned!(e.span()=> crate::calc::rules::values(#access, &F, #e, __at, __v);),
        );
    }
    if f.rules.min_len.is_some() || f.rules.max_len.is_some() {
        let min = opt_usize(f.rules.min_len.as_ref());
        let max = opt_usize(f.rules.max_len.as_ref());
        body.push(quote!(crate::calc::rules::len(#access, &F, #min, #max, __at, __v);));
    }
    quote! {
        {
            #at
            const F: crate::calc::rules::Field = crate::calc::rules::Field {
                name: #wire, unit: #unit, code: #code,
            };
            #(#body)*
            crate::calc::rules::Rules::check_rules(#access, __at, __v);
        }
    }
}

fn opt_usize(e: Option<&Expr>) -> Ts {
    match e {
        Some(e) => quote!(::core::option::Option::Some(#e)),
        None => quote!(::core::option::Option::None),
    }
}

/// The document side of one field: its rules as keywords, and the recursion into its type.
fn document_field(f: &FieldSpec<'_>) -> (Vec<Ts>, Ts) {
    let ty = f.ty;
    let p = &f.schema_ptr;
    let mut pushes = Vec::new();
    if let Some(e) = &f.rules.range {
        pushes.push(quote!(out.push(&schema, #p, crate::calc::rules::Kind::Range(#e));));
    }
    if let Some(e) = &f.rules.items {
        let p = format!("{p}/items");
        pushes.push(quote!(out.push(&schema, #p, crate::calc::rules::Kind::Range(#e));));
    }
    if let Some(e) = &f.rules.items_items {
        let p = format!("{p}/items/items");
        pushes.push(quote!(out.push(&schema, #p, crate::calc::rules::Kind::Range(#e));));
    }
    if let Some(e) = &f.rules.values {
        let p = format!("{p}/additionalProperties");
        pushes.push(quote!(out.push(&schema, #p, crate::calc::rules::Kind::Range(#e));));
    }
    if f.rules.min_len.is_some() || f.rules.max_len.is_some() {
        let min = opt_usize(f.rules.min_len.as_ref());
        let max = opt_usize(f.rules.max_len.as_ref());
        pushes.push(quote!(out.push(&schema, #p, crate::calc::rules::Kind::Len {
            min: #min, max: #max,
            string: <#ty as crate::calc::rules::HasLen>::STRING,
        });));
    }
    // A fixed-size array's length is part of the Rust type (serde enforces it): the document
    // states it too, for the field itself or each item of a list of them.
    for (len, suffix) in fixed_arrays(ty) {
        let p = format!("{p}{suffix}");
        pushes.push(quote!(out.push(&schema, #p, crate::calc::rules::Kind::Len {
            min: ::core::option::Option::Some(#len), max: ::core::option::Option::Some(#len),
            string: false,
        });));
    }
    let recurse = quote!(<#ty as crate::calc::rules::Rules>::document_rules(out););
    (pushes, recurse)
}

/// The fixed lengths inside a field's type, with where they apply: `[T; N]` and `Option<[T; N]>`
/// at the field itself, `Vec<[T; N]>` at each item, and nested arrays (`[[T; 2]; 2]`) below.
fn fixed_arrays(ty: &Type) -> Vec<(Expr, String)> {
    fn inner(ty: &Type, name: &str) -> Option<Type> {
        let Type::Path(p) = ty else { return None };
        let seg = p.path.segments.last()?;
        if seg.ident != name {
            return None;
        }
        let syn::PathArguments::AngleBracketed(a) = &seg.arguments else {
            return None;
        };
        match a.args.first()? {
            syn::GenericArgument::Type(t) => Some(t.clone()),
            _ => None,
        }
    }
    fn arrays(ty: &Type, at: String, out: &mut Vec<(Expr, String)>) {
        if let Type::Array(a) = ty {
            out.push((a.len.clone(), at.clone()));
            arrays(&a.elem, format!("{at}/items"), out);
        }
    }
    let ty = inner(ty, "Option").unwrap_or_else(|| ty.clone());
    let mut out = Vec::new();
    match inner(&ty, "Vec") {
        Some(item) => arrays(&item, "/items".to_owned(), &mut out),
        None => arrays(&ty, String::new(), &mut out),
    }
    out
}

/// The named fields of a struct or struct variant.
fn named_fields<'a>(
    fields: &'a syn::FieldsNamed,
    rename_all: Option<&str>,
    container_default: bool,
    access: impl Fn(&syn::Ident) -> Ts,
    schema_base: &str,
) -> syn::Result<Vec<FieldSpec<'a>>> {
    let mut out = Vec::new();
    for field in &fields.named {
        let Some(ident) = field.ident.as_ref() else {
            continue;
        };
        let sf = serde_field(&field.attrs)?;
        let rules = field_rules(&field.attrs)?;
        if sf.skip {
            if !rules.is_empty() {
                return Err(syn::Error::new(
                    field.span(),
                    "a field serde skips cannot carry rules",
                ));
            }
            continue;
        }
        let optional = sf.default || container_default;
        if optional && !is_option(&field.ty) && !sf.custom_de {
            return Err(syn::Error::new(
                field.ty.span(),
                "an optional field must read `null` as absent: make it an `Option` or add \
                 `deserialize_with = \"crate::calc::rules::null_default\"` (or another null-aware reader)",
            ));
        }
        let raw = ident.to_string();
        let raw = raw.strip_prefix("r#").unwrap_or(&raw).to_owned();
        let wire = sf.rename.unwrap_or_else(|| rename(&raw, rename_all));
        let schema_ptr = format!("{schema_base}/properties/{}", escape_pointer(&wire));
        out.push(FieldSpec {
            access: access(ident),
            wire,
            ty: &field.ty,
            unit: unit_of(&field.attrs),
            rules,
            schema_ptr,
            span: field.span(),
        });
    }
    Ok(out)
}

fn escape_pointer(token: &str) -> String {
    token.replace('~', "~0").replace('/', "~1")
}

fn expand(input: &DeriveInput) -> syn::Result<Ts> {
    let sc = serde_container(&input.attrs)?;
    let cr = container_rules(&input.attrs)?;
    let mut checks: Vec<Ts> = Vec::new();
    let mut pushes: Vec<Ts> = Vec::new();
    let mut recursions: Vec<Ts> = Vec::new();

    match &input.data {
        Data::Struct(s) => {
            if let Fields::Unnamed(u) = &s.fields
                && u.unnamed.len() == 1
            {
                // A newtype: its value is checked as the inner type.
                let ty = &u.unnamed[0].ty;
                checks.push(quote!(crate::calc::rules::Rules::check_rules(&self.0, __at, __v);));
                recursions.push(quote!(<#ty as crate::calc::rules::Rules>::document_rules(out);));
                return Ok(finish(input, checks, pushes, recursions));
            }
            let Fields::Named(named) = &s.fields else {
                return Err(syn::Error::new(
                    input.span(),
                    "Rules: only structs with named fields or newtypes",
                ));
            };
            let specs = named_fields(
                named,
                sc.rename_all.as_deref(),
                sc.default,
                |i| quote!(&self.#i),
                "",
            )?;
            let mut one_of_pushes = Vec::new();
            for (group, at_object) in &cr.one_of {
                let mut entries = Vec::new();
                let mut wires = Vec::new();
                for name in group {
                    let Some(f) = specs.iter().find(|f| f.wire == name.value()) else {
                        return Err(syn::Error::new(
                            name.span(),
                            "one_of names a field that is not on the wire",
                        ));
                    };
                    let access = &f.access;
                    entries.push(quote!((#name, crate::calc::rules::Present::present(#access))));
                    wires.push(name.clone());
                }
                let code = code_tokens(None, cr.code.as_ref());
                checks.push(quote!(crate::calc::rules::one_of(&[#(#entries),*], #code, #at_object, __at, __v);));
                one_of_pushes.push(
                    quote!(out.push(&schema, "", crate::calc::rules::Kind::OneOf(&[#(#wires),*]));),
                );
            }
            for f in &specs {
                checks.push(check_field(f, cr.code.as_ref(), true));
                let (p, r) = document_field(f);
                pushes.extend(p);
                recursions.push(r);
                let _ = f.span;
            }
            // After the fields' own rules, so each alternative carries them.
            pushes.extend(one_of_pushes);
        }
        Data::Enum(e) => {
            if !cr.one_of.is_empty() {
                return Err(syn::Error::new(
                    input.span(),
                    "Rules: one_of applies to structs",
                ));
            }
            let external = sc.tag.is_none() && !sc.untagged;
            let mut arms = Vec::new();
            for (i, var) in e.variants.iter().enumerate() {
                let vid = &var.ident;
                let vserde = serde_field(&var.attrs)?;
                let vwire = vserde
                    .rename
                    .clone()
                    .unwrap_or_else(|| rename(&vid.to_string(), sc.rename_all.as_deref()));
                let var_rename_all = serde_container(&var.attrs)?.rename_all;
                let base = if external {
                    format!("/oneOf/{i}/properties/{}", escape_pointer(&vwire))
                } else {
                    format!("/oneOf/{i}")
                };
                let enter = if external {
                    quote!(let __at = __at.key(#vwire);)
                } else {
                    quote!()
                };
                match &var.fields {
                    Fields::Unit => arms.push(quote!(Self::#vid => {})),
                    Fields::Unnamed(u) if u.unnamed.len() == 1 => {
                        let ty = &u.unnamed[0].ty;
                        let rules = field_rules(&var.attrs)?;
                        let spec = FieldSpec {
                            access: quote!(x),
                            wire: vwire.clone(),
                            ty,
                            unit: unit_of(&var.attrs),
                            rules,
                            schema_ptr: base.clone(),
                            span: var.span(),
                        };
                        let check = check_field(&spec, cr.code.as_ref(), false);
                        arms.push(quote!(Self::#vid(x) => { #enter #check }));
                        let (p, r) = document_field(&spec);
                        pushes.extend(p);
                        recursions.push(r);
                    }
                    Fields::Unnamed(_) => {
                        return Err(syn::Error::new(
                            var.span(),
                            "Rules: tuple variants with more than one field are not supported",
                        ));
                    }
                    Fields::Named(named) => {
                        let bound = |i: &syn::Ident| quote::format_ident!("__field_{}", i);
                        let specs = named_fields(
                            named,
                            var_rename_all.as_deref(),
                            false,
                            |i| {
                                let b = bound(i);
                                quote!(#b)
                            },
                            &base,
                        )?;
                        let binds: Vec<Ts> = named
                            .named
                            .iter()
                            .filter_map(|f| f.ident.as_ref())
                            .map(|i| {
                                let b = bound(i);
                                quote!(#i: #b)
                            })
                            .collect();
                        let field_checks: Vec<Ts> = specs
                            .iter()
                            .map(|f| check_field(f, cr.code.as_ref(), true))
                            .collect();
                        arms.push(quote!(Self::#vid { #(#binds),* } => {
                            #enter
                            #(#field_checks)*
                        }));
                        for f in &specs {
                            let (p, r) = document_field(f);
                            pushes.extend(p);
                            recursions.push(r);
                        }
                    }
                }
            }
            if arms.is_empty() {
                checks.push(quote!(let _ = (__at, __v);));
            } else {
                checks.push(quote!(
                    #[allow(unused_variables)]
                    match self { #(#arms)* }
                ));
            }
        }
        Data::Union(_) => {
            return Err(syn::Error::new(
                input.span(),
                "Rules: unions are not supported",
            ));
        }
    }

    Ok(finish(input, checks, pushes, recursions))
}

/// The impl block.
fn finish(input: &DeriveInput, checks: Vec<Ts>, pushes: Vec<Ts>, recursions: Vec<Ts>) -> Ts {
    let ident = &input.ident;
    let (impl_g, ty_g, where_c) = input.generics.split_for_impl();
    let own = if pushes.is_empty() {
        quote!()
    } else {
        quote! {
            let schema = <Self as ::utoipa::ToSchema>::name();
            if out.enter(&schema) {
                #(#pushes)*
            }
        }
    };
    let uses_at = !checks.is_empty();
    let sig_at = if uses_at { quote!(__at) } else { quote!(_at) };
    let sig_v = if uses_at { quote!(__v) } else { quote!(_v) };
    quote! {
        #[automatically_derived]
        impl #impl_g crate::calc::rules::Rules for #ident #ty_g #where_c {
            #[allow(unused_variables, clippy::too_many_lines)]
            fn check_rules(&self, #sig_at: crate::calc::rules::At<'_>, #sig_v: &mut crate::calc::Validator) {
                #(#checks)*
            }
            #[allow(clippy::too_many_lines)]
            fn document_rules(out: &mut crate::calc::rules::DocRules) {
                #own
                #(#recursions)*
            }
        }
    }
}
