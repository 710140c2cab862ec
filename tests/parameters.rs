//! Each render setting is declared once, in `src/render/settings.rs`, and each material
//! parameter in `src/scene/material.rs`. This test proves that what the other languages hold
//! follows from the declarations: the C structs and their conversions, the C++ wrappers, the
//! Python dataclasses, `docs/settings.md` and the C++ check program
//! `c_examples/parameters.cpp` are generated from them, and must equal what is committed. `MLT_BLESS=1 cargo test --test parameters` rewrites them (then build, to
//! regenerate `include/mlt.h`). The values every front end sees are checked where each
//! front end is run: `c_hosts.rs` (C and C++), `cli.rs` (the command line) and
//! `python/tests/test_parameters.py`. Takes under a second.

use mlt::params::{Kind, Parameter, Parameters, Value};
use mlt::{Material, RenderSettings};
use std::path::{Path, PathBuf};

fn settings() -> &'static [Parameter<RenderSettings>] {
    RenderSettings::parameters()
}

fn materials() -> &'static [Parameter<Material>] {
    Material::parameters()
}

/// The choices that have a Python enum (`python/mlt/_types.py`); the others are strings.
const PYTHON_ENUMS: [&str; 1] = ["Algorithm"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The default of `p`.
fn default<S>(p: &Parameter<S>) -> Value {
    (p.default)()
}

/// A float as Rust prints it, with a decimal point or exponent (a literal in every language).
fn float_literal(text: String) -> String {
    if text.contains(['.', 'e', 'i', 'N']) {
        text
    } else {
        format!("{text}.0")
    }
}

/// The number `v` of kind `kind` as a literal (floats: the shortest text of their type).
fn number(kind: Kind, v: &Value) -> String {
    match (kind, v) {
        (_, Value::Int(i)) => i.to_string(),
        (Kind::F32 | Kind::F32x3 | Kind::F32x4, Value::Float(f)) => {
            float_literal(short_f32(*f as f32))
        }
        (_, Value::Float(f)) => float_literal(format!("{f:?}")),
        _ => unreachable!("not a number: {v:?}"),
    }
}

/// The shortest text that reads back as `v`, in exponent form when long.
fn short_f32(v: f32) -> String {
    let plain = v.to_string();
    let exponent = format!("{v:e}");
    if exponent.len() < plain.len() {
        exponent
    } else {
        plain
    }
}

/// "path-space-mlt" → "PATH_SPACE_MLT".
fn upper(name: &str) -> String {
    name.replace('-', "_").to_uppercase()
}

/// "path-space-mlt" → "PathSpaceMlt".
fn camel(name: &str) -> String {
    name.split(['-', '_'])
        .map(|w| {
            let mut c = w.chars();
            c.next()
                .map(|f| f.to_uppercase().chain(c).collect::<String>())
                .unwrap_or_default()
        })
        .collect()
}

/// The numbers of a value of several, as `number` writes each.
fn numbers(kind: Kind, v: &Value) -> Vec<String> {
    let each = |x: &f32| number(kind, &Value::Float((*x).into()));
    match v {
        Value::Vec3(v) => v.iter().map(each).collect(),
        Value::Floats(v) => v.iter().map(each).collect(),
        v => vec![number(kind, v)],
    }
}

/// What values `p` accepts, as a sentence.
fn valid<S: Parameters>(p: &Parameter<S>) -> String {
    match (p.kind, p.rule) {
        (_, Some(rule)) => {
            let text = rule(&S::default());
            let mut c = text.chars();
            let first = c.next().map(|f| f.to_uppercase().collect::<String>());
            first.unwrap_or_default() + c.as_str()
        }
        (Kind::Bool, None) => "True or false".into(),
        (Kind::Choice(choices), None) => format!("One of {}", choices.names.join(", ")),
        (Kind::Texture, None) => "None, or a texture with its transform".into(),
        (Kind::F32 | Kind::F64 | Kind::F32x3 | Kind::F32x4, None) => "Any finite number".into(),
        _ => "Any value of its type".into(),
    }
}

/// `text` wrapped at 100 columns, each line starting with `prefix`.
fn wrapped(prefix: &str, text: &str) -> String {
    let mut out = String::new();
    let mut line = prefix.to_owned();
    for word in text.split_whitespace() {
        if line.len() > prefix.len() && line.len() + 1 + word.len() > 100 {
            out += &line;
            out.push('\n');
            line = prefix.to_owned();
        }
        line.push(' ');
        line += word;
    }
    out + &line + "\n"
}

// --- C: the structs (src/capi/types.rs) and their conversions ---

fn c_type(kind: Kind) -> &'static str {
    match kind {
        Kind::U32 | Kind::Bool => "u32",
        Kind::U64 => "u64",
        Kind::F32 => "f32",
        Kind::F64 => "f64",
        Kind::Choice(_) => "i32",
        Kind::F32x3 => "[f32; 3]",
        Kind::F32x4 => "[f32; 4]",
        Kind::Texture => "MltTextureRef",
    }
}

/// The C default as the header's reader writes it.
fn c_default<S>(p: &Parameter<S>) -> String {
    match (p.kind, default(p)) {
        (_, Value::Bool(b)) => (b as u32).to_string(),
        (Kind::Choice(choices), Value::Choice(c)) => format!("`{}`", choices.c_constant(c)),
        (_, Value::Texture(None)) => "`MLT_NO_TEXTURE` (-1)".into(),
        (kind, v) => numbers(kind, &v).join(", "),
    }
}

/// A field of a C struct that is no parameter of its own.
struct COnlyField {
    /// The parameter it follows: the last one when it was added, as the C struct only grows
    /// at its end.
    after: &'static str,
    name: &'static str,
    c_type: &'static str,
    doc: &'static str,
}

/// `MltMaterial`'s fields beyond its parameters: what the other languages hold in each
/// texture slot (`TextureRef::texcoord`), which `MltTextureRef` cannot hold without moving
/// every later field.
const MATERIAL_C_ONLY: [COnlyField; 1] = [COnlyField {
    after: "iridescence_thickness_texture",
    name: "texcoord1_slots",
    c_type: "u32",
    doc: "The texture slots that read texture coordinate set 1 (`MltSceneDesc.texcoords1`, glTF's \
          texCoord 1) instead of set 0: bit i is the i-th texture slot in field order, \
          `MLT_TEXCOORD1_<SLOT>` (`MLT_TEXCOORD1_BASE_COLOR` is bit 0). A bit past the last slot \
          is refused; a bit of a slot without a texture is ignored. Default 0: every slot reads \
          set 0.",
}];

/// The texture slots in declaration order, the order of `MltMaterial.texcoord1_slots`' bits.
fn texture_slots() -> impl Iterator<Item = &'static str> {
    materials()
        .iter()
        .filter(|p| matches!(p.kind, Kind::Texture))
        .map(|p| p.name)
}

/// `MLT_TEXCOORD1_BASE_COLOR` for `base_color_texture`.
fn texcoord1_constant(slot: &str) -> String {
    format!(
        "MLT_TEXCOORD1_{}",
        upper(slot.strip_suffix("_texture").unwrap_or(slot))
    )
}

/// The C constants of `MltMaterial.texcoord1_slots`' bits.
fn c_texcoord1_constants() -> String {
    texture_slots()
        .enumerate()
        .map(|(i, slot)| {
            format!(
                "/// `MltMaterial.texcoord1_slots`: `{slot}` reads texture coordinate set 1.\n\
                 pub const {}: u32 = 1 << {i};\n",
                texcoord1_constant(slot)
            )
        })
        .collect()
}

fn c_struct_fields<S: Parameters>(c_only: &[COnlyField]) -> String {
    let mut out = String::new();
    for p in S::parameters() {
        let valid = match p.kind {
            Kind::Bool => "0 or 1".into(),
            Kind::Choice(choices) => format!("One of `{}_*`", choices.c_prefix),
            Kind::Texture => "An index into `MltSceneDesc.textures` and its transform".into(),
            _ => valid(p),
        };
        out += &wrapped(
            "    ///",
            &format!("{} {valid}. Default {}.", p.doc, c_default(p)),
        );
        out += &format!("    pub {}: {},\n", p.name, c_type(p.kind));
        for field in c_only.iter().filter(|f| f.after == p.name) {
            out += &wrapped("    ///", field.doc);
            out += &format!("    pub {}: {},\n", field.name, field.c_type);
        }
    }
    out
}

fn names_list<S: Parameters>(indent: &str) -> String {
    S::parameters()
        .iter()
        .map(|p| format!("{indent}{},\n", p.name))
        .collect()
}

// --- C++: include/mlt.hpp's RenderSettings and Material ---

fn cpp_type<S>(p: &Parameter<S>) -> String {
    match p.kind {
        Kind::U32 => "std::uint32_t".into(),
        Kind::U64 => "std::uint64_t".into(),
        Kind::F32 => "float".into(),
        Kind::F64 => "double".into(),
        Kind::Bool => "bool".into(),
        Kind::Choice(choices) => choices.type_name.into(),
        Kind::F32x3 => "std::array<float, 3>".into(),
        Kind::F32x4 => "std::array<float, 4>".into(),
        Kind::Texture => "TextureRef".into(),
    }
}

/// `v` as a C++ expression of `p`'s type.
fn cpp_value<S>(p: &Parameter<S>, v: &Value) -> String {
    match (p.kind, v) {
        (_, Value::Bool(b)) => b.to_string(),
        (Kind::Choice(choices), Value::Choice(c)) => format!("{}::{}", choices.type_name, camel(c)),
        (_, Value::Texture(_)) => "{}".into(),
        (Kind::F32 | Kind::F32x3 | Kind::F32x4, v) => {
            let floats: Vec<String> = numbers(Kind::F32, v).into_iter().map(|x| x + "f").collect();
            match v {
                Value::Float(_) => floats.join(""),
                _ => format!("{{{}}}", floats.join(", ")),
            }
        }
        (kind, v) => number(kind, v),
    }
}

fn cpp_members<S: Parameters>() -> String {
    let mut out = String::new();
    for p in S::parameters() {
        out += &wrapped("    ///", p.doc);
        out += &format!(
            "    {} {}{};\n",
            cpp_type(p),
            p.name,
            match p.kind {
                Kind::Texture => String::new(),
                Kind::F32x3 | Kind::F32x4 => cpp_value(p, &default(p)),
                _ => format!(" = {}", cpp_value(p, &default(p))),
            }
        );
    }
    out
}

fn cpp_to_c<S: Parameters>() -> String {
    S::parameters()
        .iter()
        .map(|p| {
            let n = p.name;
            match p.kind {
                Kind::Bool => format!("        c.{n} = {n} ? 1u : 0u;\n"),
                Kind::Choice(_) => format!("        c.{n} = detail::c_value({n});\n"),
                Kind::F32x3 | Kind::F32x4 => format!("        detail::copy_to(c.{n}, {n});\n"),
                Kind::Texture => format!(
                    "        c.{n} =\n            {n}.to_c(\"{n}\", {}, c.texcoord1_slots);\n",
                    texcoord1_constant(n)
                ),
                _ => format!("        c.{n} = {n};\n"),
            }
        })
        .collect()
}

/// The assignments of `from_c` to the C++ value `var`.
fn cpp_from_c<S: Parameters>(var: &str) -> String {
    S::parameters()
        .iter()
        .map(|p| {
            let n = p.name;
            match p.kind {
                Kind::Bool => format!("        {var}.{n} = c.{n} != 0;\n"),
                Kind::Choice(choices) => format!(
                    "        {var}.{n} = detail::from_c<{}>(c.{n});\n",
                    choices.type_name
                ),
                Kind::F32x3 | Kind::F32x4 => {
                    format!("        {var}.{n} = detail::to_array(c.{n});\n")
                }
                Kind::Texture => format!(
                    "        {var}.{n} =\n            TextureRef::from_c(c.{n}, c.texcoord1_slots & {});\n",
                    texcoord1_constant(n)
                ),
                _ => format!("        {var}.{n} = c.{n};\n"),
            }
        })
        .collect()
}

/// The check program's constants: every choice's C values are 0, 1, … in the declared
/// order, which the C conversions rely on.
fn cpp_constants() -> String {
    let kinds = settings()
        .iter()
        .map(|p| p.kind)
        .chain(materials().iter().map(|p| p.kind));
    let mut out = String::new();
    for kind in kinds {
        let Kind::Choice(choices) = kind else {
            continue;
        };
        let values: Vec<String> = choices
            .names
            .iter()
            .enumerate()
            .map(|(i, n)| format!("{} == {i}", choices.c_constant(n)))
            .collect();
        out += &format!(
            "static_assert({}, \"{}_* are 0, 1, ... in the declared order\");\n",
            values.join(" && "),
            choices.c_prefix
        );
    }
    out
}

/// The check program's body for one struct: each parameter's default as C (`c`) and C++
/// (`cpp`) see it, then the message mlt gives for an out-of-range value set through each
/// (`message(language, name, C struct)` prints it). Names are prefixed with `label`.
fn cpp_checks<S: Parameters>(label: &str, cpp_struct: &str, c_struct: &str) -> String {
    let mut out = String::new();
    for p in S::parameters() {
        out += &format!(
            "    show(\"c\", \"{label}{n}\", c.{n});\n    show(\"c++\", \"{label}{n}\", cpp.{n});\n",
            n = p.name
        );
    }
    for p in S::parameters() {
        let Some(bad) = p.outside_value() else {
            continue;
        };
        let n = p.name;
        let value = cpp_value(p, &bad);
        out += &format!("    {{\n        mlt::{cpp_struct} s;\n        s.{n} = {value};\n");
        out += &format!("        message(\"c++\", \"{label}{n}\", s.to_c());\n");
        out += &format!("        {c_struct} cs = c;\n");
        out += &match p.kind {
            Kind::F32x3 | Kind::F32x4 => format!(
                "        const {} bad{value};\n        for (std::size_t i = 0; i < bad.size(); ++i) cs.{n}[i] = bad[i];\n",
                cpp_type(p)
            ),
            _ => format!("        cs.{n} = {value};\n"),
        };
        out += &format!("        message(\"c\", \"{label}{n}\", cs);\n    }}\n");
    }
    out
}

// --- Python: python/mlt/_types.py's RenderSettings and Material ---

fn python_type<S>(p: &Parameter<S>) -> String {
    match p.kind {
        Kind::U32 | Kind::U64 => "int".into(),
        Kind::F32 | Kind::F64 => "float".into(),
        Kind::Bool => "bool".into(),
        Kind::Choice(choices) if PYTHON_ENUMS.contains(&choices.type_name) => {
            format!("Union[{}, str]", choices.type_name)
        }
        Kind::Choice(_) => "str".into(),
        Kind::F32x3 => "Vec3".into(),
        Kind::F32x4 => "Tuple[float, float, float, float]".into(),
        Kind::Texture => "Optional[TextureRef]".into(),
    }
}

fn python_value<S>(p: &Parameter<S>, v: &Value) -> String {
    match (p.kind, v) {
        (_, Value::Bool(true)) => "True".into(),
        (_, Value::Bool(false)) => "False".into(),
        (Kind::Choice(choices), Value::Choice(c)) if PYTHON_ENUMS.contains(&choices.type_name) => {
            format!("{}.{}", choices.type_name, upper(c))
        }
        (_, Value::Choice(c)) => format!("{c:?}"),
        (_, Value::Texture(_)) => "None".into(),
        (_, Value::Vec3(_) | Value::Floats(_)) => {
            format!("({})", numbers(Kind::F32, v).join(", "))
        }
        (kind, v) => number(kind, v),
    }
}

fn python_fields<S: Parameters>() -> String {
    let mut out = String::new();
    for p in S::parameters() {
        out += &wrapped("    #:", p.doc);
        out += &format!(
            "    {}: {} = {}\n",
            p.name,
            python_type(p),
            python_value(p, &default(p))
        );
    }
    out
}

// --- docs/settings.md ---

fn docs_kind(kind: Kind) -> &'static str {
    match kind {
        Kind::U32 => "u32",
        Kind::U64 => "u64",
        Kind::F32 => "f32",
        Kind::F64 => "f64",
        Kind::Bool => "bool",
        Kind::Choice(_) => "name",
        Kind::F32x3 => "3 × f32",
        Kind::F32x4 => "4 × f32",
        Kind::Texture => "texture",
    }
}

fn docs_default<S>(p: &Parameter<S>) -> String {
    match default(p) {
        Value::Choice(c) => format!("`{c}`"),
        Value::Bool(b) => b.to_string(),
        Value::Texture(None) => "none".into(),
        v => numbers(p.kind, &v).join(", "),
    }
}

fn docs() -> String {
    let mut out = String::from(
        "# Render settings and material parameters\n\n\
         Every setting of a render, as `src/render/settings.rs` declares it, and every parameter\n\
         of a material, as `src/scene/material.rs` does. This page is generated:\n\
         `MLT_BLESS=1 cargo test --test parameters` rewrites it.\n\n\
         ## Render settings\n\n\
         The C field of `MltRenderSettings` (`include/mlt.h`), the member of\n\
         `mlt::RenderSettings` (`include/mlt.hpp`), the Rust field of `mlt::RenderSettings`, the\n\
         keyword of `mlt.RenderSettings` in Python and the flag of `mlt-render` all have the\n\
         name, default and valid values below; a value outside them is refused with the same\n\
         message everywhere, `settings.<name> is <value>; <valid values>`. Booleans are 0 or 1\n\
         in C.\n\n\
         | Setting | Type | Default | Valid values | Command line | What it does |\n\
         |---|---|---|---|---|---|\n",
    );
    for p in settings() {
        let flag = p.flag.expect("every setting has a flag");
        let flag = match p.kind {
            Kind::Bool => format!("`--{flag}`"),
            Kind::Choice(_) => format!("`--{flag} NAME`"),
            Kind::U32 | Kind::U64 => format!("`--{flag} N`"),
            Kind::F32x4 => format!("`--{flag} B,L,C,M`"),
            _ => format!("`--{flag} X`"),
        };
        out += &format!(
            "| `{}` | {} | {} | {} | {flag} | {} |\n",
            p.name,
            docs_kind(p.kind),
            docs_default(p),
            valid(p),
            p.doc
        );
    }
    out += "\n## Material parameters\n\n\
         The C field of `MltMaterial`, the member of `mlt::Material`, the Rust field of\n\
         `mlt::Material` and the keyword of `mlt.Material` in Python all have the name, default\n\
         and valid values below; a value outside them is refused with the same message\n\
         everywhere, `desc.materials[<index>].<name> is <value>; <valid values>`. The command\n\
         line sets a parameter on every material of the scene it loads with\n\
         `--material NAME=VALUE` (a texture slot takes `none` or a texture's index). Every\n\
         number must be finite. Choices are `MLT_MATERIAL_*` and `MLT_ALPHA_*` in C, texture\n\
         slots `MltTextureRef`. A texture slot reads texture coordinate set 0 (`texcoords`), or\n\
         set 1 (`texcoords1`) where its `texcoord` is 1: in C, where its bit of\n\
         `MltMaterial.texcoord1_slots` (`MLT_TEXCOORD1_<SLOT>`) is set.\n\n\
         | Parameter | Type | Default | Valid values | What it does |\n\
         |---|---|---|---|---|\n";
    for p in materials() {
        out += &format!(
            "| `{}` | {} | {} | {} | {} |\n",
            p.name,
            docs_kind(p.kind),
            docs_default(p),
            valid(p),
            p.doc
        );
    }
    out
}

// --- checking and rewriting ---

/// Replaces the lines between the lines holding `BEGIN GENERATED <tag>` and `END GENERATED
/// <tag>` of `text`.
fn with_block(text: &str, tag: &str, block: &str, path: &Path) -> String {
    let begin = format!("BEGIN GENERATED {tag}");
    let end = format!("END GENERATED {tag}");
    let start = text
        .find(&begin)
        .unwrap_or_else(|| panic!("{} has no {begin:?} line", path.display()));
    let start = start + text[start..].find('\n').expect("a line after BEGIN") + 1;
    let stop = start
        + text[start..]
            .find(&end)
            .unwrap_or_else(|| panic!("{} has no {end:?} line", path.display()));
    let stop = text[..stop].rfind('\n').expect("END on a line of its own") + 1;
    format!("{}{block}{}", &text[..start], &text[stop..])
}

/// Compares each generated file with what is committed; rewrites them with `MLT_BLESS`.
#[test]
fn generated_code_and_docs_follow_the_declarations() {
    type S = RenderSettings;
    type M = Material;
    let blocks: [(&str, &str, String); 19] = [
        (
            "src/capi/types.rs",
            "render settings",
            c_struct_fields::<S>(&[]),
        ),
        (
            "src/capi/types.rs",
            "material",
            c_struct_fields::<M>(&MATERIAL_C_ONLY),
        ),
        (
            "src/capi/types.rs",
            "texcoord1 slots",
            c_texcoord1_constants(),
        ),
        (
            "src/capi/convert.rs",
            "settings from C",
            names_list::<S>("        "),
        ),
        (
            "src/capi/convert.rs",
            "material from C",
            names_list::<M>("        "),
        ),
        (
            "src/capi/extensible.rs",
            "settings to C",
            names_list::<S>("            "),
        ),
        (
            "src/capi/extensible.rs",
            "material to C",
            names_list::<M>("            "),
        ),
        ("include/mlt.hpp", "settings members", cpp_members::<S>()),
        ("include/mlt.hpp", "settings to C", cpp_to_c::<S>()),
        ("include/mlt.hpp", "settings from C", cpp_from_c::<S>("s")),
        ("include/mlt.hpp", "material members", cpp_members::<M>()),
        ("include/mlt.hpp", "material to C", cpp_to_c::<M>()),
        ("include/mlt.hpp", "material from C", cpp_from_c::<M>("m")),
        (
            "python/mlt/_types.py",
            "render settings",
            python_fields::<S>(),
        ),
        ("python/mlt/_types.py", "material", python_fields::<M>()),
        ("c_examples/parameters.cpp", "constants", cpp_constants()),
        (
            "c_examples/parameters.cpp",
            "settings checks",
            cpp_checks::<S>("", "RenderSettings", "MltRenderSettings"),
        ),
        (
            "c_examples/parameters.cpp",
            "material checks",
            cpp_checks::<M>("material.", "Material", "MltMaterial"),
        ),
        ("docs/settings.md", "", docs()),
    ];
    let bless = std::env::var_os("MLT_BLESS").is_some();
    let mut stale = Vec::new();
    for (file, tag, block) in blocks {
        let path = root().join(file);
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        let generated = if tag.is_empty() {
            block
        } else {
            with_block(&committed, tag, &block, &path)
        };
        if generated != committed {
            if bless {
                std::fs::write(&path, &generated).unwrap();
            } else {
                stale.push(format!("{file} ({tag})"));
            }
        }
    }
    assert!(
        stale.is_empty(),
        "out of date with the declarations in src/render/settings.rs and src/scene/material.rs: {stale:?}; run `MLT_BLESS=1 cargo test --test parameters`, then build"
    );
}

/// Every declaration is complete: a doc, a flag of its own, a range and rule together, a
/// value outside the range when it has one, and a default inside.
#[test]
fn every_declaration_is_complete() {
    let mut flags = std::collections::BTreeSet::new();
    for p in settings() {
        assert!(p.doc.ends_with('.') && !p.doc.contains('\n'), "{}", p.name);
        let flag = p.flag.expect("every setting has a flag");
        assert!(flags.insert(flag), "two settings have --{flag}");
        assert_eq!(p.range.is_some(), p.rule.is_some(), "{}", p.name);
        let defaults = RenderSettings::default();
        assert_eq!(defaults.get(p.name), Some(default(p)), "{}", p.name);
        if let Some(bad) = p.outside_value() {
            let mut s = RenderSettings::default();
            s.set(p.name, bad).unwrap();
            let message = s.validate().unwrap_err().message;
            assert!(
                message.starts_with(&format!("settings.{}", p.name)),
                "{}: {message}",
                p.name
            );
        }
    }
    RenderSettings::default().validate().unwrap();
    for p in materials() {
        assert!(p.doc.ends_with('.') && !p.doc.contains('\n'), "{}", p.name);
        assert!(p.flag.is_none(), "{}: materials are set by name", p.name);
        assert_eq!(p.range.is_some(), p.rule.is_some(), "{}", p.name);
        assert_eq!(
            Material::default().get(p.name),
            Some(default(p)),
            "{}",
            p.name
        );
        if let Some(bad) = p.outside_value() {
            let mut m = Material::default();
            m.set(p.name, bad).unwrap();
            let message = m.validate(3, 0).unwrap_err().message;
            assert!(
                message.starts_with(&format!("desc.materials[3].{}", p.name)),
                "{}: {message}",
                p.name
            );
        }
    }
    Material::default().validate(0, 0).unwrap();
}

/// Setting by name refuses what the field cannot hold, with the rule's message.
#[test]
fn set_by_name_refuses_with_the_rule() {
    let mut s = RenderSettings::default();
    let e = s.set("width", Value::Int(-1)).unwrap_err();
    assert_eq!(
        e.message,
        "settings.width is -1; it must be between 1 and 65536"
    );
    let e = s.set("width", Value::Float(1.5)).unwrap_err();
    assert_eq!(e.message, "settings.width is 1.5; it takes an integer");
    let e = s.set("no_such_setting", Value::Int(1)).unwrap_err();
    assert!(e.message.contains("no parameter \"no_such_setting\""));
    let e = s.set("algorithm", Value::Choice("fast")).unwrap_err();
    assert!(
        e.message.contains("expected one of \"path\""),
        "{}",
        e.message
    );
    s.set("algorithm", Value::Choice("PATH_SPACE_MLT")).unwrap();
    assert_eq!(s.algorithm, mlt::Algorithm::PathSpaceMlt);
}
