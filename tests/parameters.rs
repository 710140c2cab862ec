//! Each render setting is declared once, in `src/render/settings.rs`. This test proves that
//! what the other languages hold follows from the declarations: the C struct and its
//! conversions, the C++ wrapper, the Python dataclass, `docs/settings.md` and the C++ check
//! program `c_examples/parameters.cpp` are generated from them, and must equal what is
//! committed. `MLT_BLESS=1 cargo test --test parameters` rewrites them (then build, to
//! regenerate `include/mlt.h`). The values every front end sees are checked where each
//! front end is run: `c_hosts.rs` (C and C++), `cli.rs` (the command line) and
//! `python/tests/test_parameters.py`. Takes under a second.

use mlt::RenderSettings;
use mlt::params::{Kind, Parameter, Parameters, Value};
use std::path::{Path, PathBuf};

fn settings() -> &'static [Parameter<RenderSettings>] {
    RenderSettings::parameters()
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The default of `p`.
fn default(p: &Parameter<RenderSettings>) -> Value {
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
        (Kind::F32 | Kind::F32x4, Value::Float(f)) => float_literal(short_f32(*f as f32)),
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

/// What values `p` accepts, as a sentence.
fn valid(p: &Parameter<RenderSettings>) -> String {
    match (p.kind, p.rule) {
        (_, Some(rule)) => {
            let text = rule(&RenderSettings::default());
            let mut c = text.chars();
            let first = c.next().map(|f| f.to_uppercase().collect::<String>());
            first.unwrap_or_default() + c.as_str()
        }
        (Kind::Bool, None) => "True or false".into(),
        (Kind::Choice(names), None) => format!("One of {}", names.join(", ")),
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

// --- C: the struct (src/capi/types.rs) and its conversions ---

fn c_type(kind: Kind) -> &'static str {
    match kind {
        Kind::U32 | Kind::Bool => "u32",
        Kind::U64 => "u64",
        Kind::F32 => "f32",
        Kind::F64 => "f64",
        Kind::Choice(_) => "i32",
        Kind::F32x4 => "[f32; 4]",
    }
}

/// The C default as the header's reader writes it.
fn c_default(p: &Parameter<RenderSettings>) -> String {
    match (p.kind, default(p)) {
        (_, Value::Bool(b)) => (b as u32).to_string(),
        (_, Value::Choice(c)) => format!("`MLT_{}_{}`", upper(p.name), upper(c)),
        (kind, Value::Floats(v)) => v.map(|x| number(kind, &Value::Float(x.into()))).join(", "),
        (kind, v) => number(kind, &v),
    }
}

fn c_struct_fields() -> String {
    let mut out = String::new();
    for p in settings() {
        let valid = match p.kind {
            Kind::Bool => "0 or 1".into(),
            Kind::Choice(_) => format!("One of `MLT_{}_*`", upper(p.name)),
            _ => valid(p),
        };
        out += &wrapped(
            "    ///",
            &format!("{} {valid}. Default {}.", p.doc, c_default(p)),
        );
        out += &format!("    pub {}: {},\n", p.name, c_type(p.kind));
    }
    out
}

fn names_list(indent: &str) -> String {
    settings()
        .iter()
        .map(|p| format!("{indent}{},\n", p.name))
        .collect()
}

// --- C++: include/mlt.hpp's RenderSettings ---

fn cpp_type(p: &Parameter<RenderSettings>) -> String {
    match p.kind {
        Kind::U32 => "std::uint32_t".into(),
        Kind::U64 => "std::uint64_t".into(),
        Kind::F32 => "float".into(),
        Kind::F64 => "double".into(),
        Kind::Bool => "bool".into(),
        Kind::Choice(_) => camel(p.name),
        Kind::F32x4 => "std::array<float, 4>".into(),
    }
}

/// `v` as a C++ expression of `p`'s type.
fn cpp_value(p: &Parameter<RenderSettings>, v: &Value) -> String {
    let f32_literal = |x: f32| number(Kind::F32, &Value::Float(x.into())) + "f";
    match v {
        Value::Bool(b) => b.to_string(),
        Value::Choice(c) => format!("{}::{}", camel(p.name), camel(c)),
        Value::Floats(v) => format!("{{{}}}", v.map(f32_literal).join(", ")),
        Value::Float(x) if p.kind == Kind::F32 => f32_literal(*x as f32),
        v => number(p.kind, v),
    }
}

fn cpp_members() -> String {
    let mut out = String::new();
    for p in settings() {
        out += &wrapped("    ///", p.doc);
        out += &format!(
            "    {} {}{};\n",
            cpp_type(p),
            p.name,
            match p.kind {
                Kind::F32x4 => cpp_value(p, &default(p)),
                _ => format!(" = {}", cpp_value(p, &default(p))),
            }
        );
    }
    out
}

fn cpp_to_c() -> String {
    settings()
        .iter()
        .map(|p| {
            let n = p.name;
            match p.kind {
                Kind::Bool => format!("        c.{n} = {n} ? 1u : 0u;\n"),
                Kind::Choice(_) => format!("        c.{n} = detail::c_value({n});\n"),
                Kind::F32x4 => format!("        detail::copy_to(c.{n}, {n});\n"),
                _ => format!("        c.{n} = {n};\n"),
            }
        })
        .collect()
}

fn cpp_from_c() -> String {
    settings()
        .iter()
        .map(|p| {
            let n = p.name;
            match p.kind {
                Kind::Bool => format!("        s.{n} = c.{n} != 0;\n"),
                Kind::Choice(_) => {
                    format!("        s.{n} = detail::from_c<{}>(c.{n});\n", camel(n))
                }
                Kind::F32x4 => format!("        s.{n} = detail::to_array(c.{n});\n"),
                _ => format!("        s.{n} = c.{n};\n"),
            }
        })
        .collect()
}

/// The check program's body: each setting's defaults as C and C++ see them, then the
/// message mlt gives for an out-of-range value set through each.
fn cpp_checks() -> String {
    let mut out = String::new();
    for p in settings() {
        out += &format!(
            "    show(\"c\", \"{n}\", c.{n});\n    show(\"c++\", \"{n}\", cpp.{n});\n",
            n = p.name
        );
    }
    for p in settings() {
        let Some(bad) = p.outside_value() else {
            continue;
        };
        let n = p.name;
        let value = cpp_value(p, &bad);
        out += &format!("    {{\n        mlt::RenderSettings s;\n        s.{n} = {value};\n");
        out += &format!("        message(\"c++\", \"{n}\", scene, s.to_c());\n");
        out += "        MltRenderSettings cs = c;\n";
        out += &match p.kind {
            Kind::F32x4 => format!(
                "        const std::array<float, 4> bad{value};\n        for (int i = 0; i < 4; ++i) cs.{n}[i] = bad[i];\n"
            ),
            _ => format!("        cs.{n} = {value};\n"),
        };
        out += &format!("        message(\"c\", \"{n}\", scene, cs);\n    }}\n");
    }
    out
}

// --- Python: python/mlt/_types.py's RenderSettings ---

fn python_type(kind: Kind) -> &'static str {
    match kind {
        Kind::U32 | Kind::U64 => "int",
        Kind::F32 | Kind::F64 => "float",
        Kind::Bool => "bool",
        Kind::Choice(_) => "Union[Algorithm, str]",
        Kind::F32x4 => "Tuple[float, float, float, float]",
    }
}

fn python_value(p: &Parameter<RenderSettings>, v: &Value) -> String {
    match v {
        Value::Bool(true) => "True".into(),
        Value::Bool(false) => "False".into(),
        Value::Choice(c) => format!("{}.{}", camel(p.name), upper(c)),
        Value::Floats(v) => format!(
            "({})",
            v.map(|x| number(Kind::F32, &Value::Float(x.into())))
                .join(", ")
        ),
        v => number(p.kind, v),
    }
}

fn python_fields() -> String {
    let mut out = String::new();
    for p in settings() {
        out += &wrapped("    #:", p.doc);
        out += &format!(
            "    {}: {} = {}\n",
            p.name,
            python_type(p.kind),
            python_value(p, &default(p))
        );
    }
    out
}

// --- docs/settings.md ---

fn docs() -> String {
    let mut out = String::from(
        "# Render settings\n\n\
         Every setting of a render, as `src/render/settings.rs` declares it: the C field of\n\
         `MltRenderSettings` (`include/mlt.h`), the member of `mlt::RenderSettings`\n\
         (`include/mlt.hpp`), the Rust field of `mlt::RenderSettings`, the keyword of\n\
         `mlt.RenderSettings` in Python and the flag of `mlt-render` all have the name, default\n\
         and valid values below; a value outside them is refused with the same message\n\
         everywhere, `settings.<name> is <value>; <valid values>`. Booleans are 0 or 1 in C.\n\
         This page is generated: `MLT_BLESS=1 cargo test --test parameters` rewrites it.\n\n\
         | Setting | Type | Default | Valid values | Command line | What it does |\n\
         |---|---|---|---|---|---|\n",
    );
    for p in settings() {
        let kind = match p.kind {
            Kind::U32 => "u32",
            Kind::U64 => "u64",
            Kind::F32 => "f32",
            Kind::F64 => "f64",
            Kind::Bool => "bool",
            Kind::Choice(_) => "name",
            Kind::F32x4 => "4 × f32",
        };
        let flag = match p.kind {
            Kind::Bool => format!("`--{}`", p.flag),
            Kind::Choice(_) => format!("`--{} NAME`", p.flag),
            Kind::U32 | Kind::U64 => format!("`--{} N`", p.flag),
            Kind::F32x4 => format!("`--{} B,L,C,M`", p.flag),
            Kind::F32 | Kind::F64 => format!("`--{} X`", p.flag),
        };
        let shown = match default(p) {
            Value::Choice(c) => format!("`{c}`"),
            Value::Bool(b) => b.to_string(),
            Value::Floats(v) => v
                .map(|x| number(Kind::F32, &Value::Float(x.into())))
                .join(", "),
            v => number(p.kind, &v),
        };
        out += &format!(
            "| `{}` | {kind} | {shown} | {} | {flag} | {} |\n",
            p.name,
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
    let blocks: [(&str, &str, String); 9] = [
        ("src/capi/types.rs", "render settings", c_struct_fields()),
        (
            "src/capi/convert.rs",
            "settings from C",
            names_list("        "),
        ),
        (
            "src/capi/extensible.rs",
            "settings to C",
            names_list("            "),
        ),
        ("include/mlt.hpp", "members", cpp_members()),
        ("include/mlt.hpp", "to C", cpp_to_c()),
        ("include/mlt.hpp", "from C", cpp_from_c()),
        ("python/mlt/_types.py", "render settings", python_fields()),
        ("c_examples/parameters.cpp", "checks", cpp_checks()),
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
        "out of date with the declarations in src/render/settings.rs: {stale:?}; run `MLT_BLESS=1 cargo test --test parameters`, then build"
    );
}

/// Every declaration is complete: a doc, a flag of its own, a range and rule together, a
/// value outside the range when it has one, and a default inside.
#[test]
fn every_declaration_is_complete() {
    let mut flags = std::collections::BTreeSet::new();
    for p in settings() {
        assert!(p.doc.ends_with('.') && !p.doc.contains('\n'), "{}", p.name);
        assert!(flags.insert(p.flag), "two settings have --{}", p.flag);
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
