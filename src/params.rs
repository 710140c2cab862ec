//! Parameters declared once. A struct of parameters (the render settings) is written as one
//! `declare_parameters!` table: each field with its type, default, valid range, the rule
//! its error message states, a one-line doc and its command-line flag. The macro makes the
//! struct, its `Default`, the range checks of its validation, access by name
//! ([`Parameters::get`], [`Parameters::set`]) and the metadata ([`Parameter`]) every front end
//! reads: the C header's struct and conversions, the C++ and Python wrappers and
//! `docs/settings.md` are generated from it (`tests/parameters.rs` checks them and rewrites
//! them with `MLT_BLESS=1`), the command line builds its flags from it at run time, the job
//! plan encodes by it and the fuzz generator draws from it.

use crate::error::{Error, Result};
use crate::texture::TextureRef;

/// The type of a parameter's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    U32,
    U64,
    F32,
    F64,
    Bool,
    /// One of these names.
    Choice(&'static Choices),
    /// Three floats (a colour or a vector), each in the range.
    F32x3,
    /// Four floats, each in the range.
    F32x4,
    /// A material's texture slot: none, or a texture with its coordinate transform.
    Texture,
}

/// The names of a choice parameter's values, and what the C and C++ APIs call them.
#[derive(Debug, PartialEq, Eq)]
pub struct Choices {
    /// The names of the command line, Python and the docs, in the order of the C values
    /// (0, 1, …).
    pub names: &'static [&'static str],
    /// The C++ `enum class` (and, where there is one, the Python enum).
    pub type_name: &'static str,
    /// The C constants' common prefix: `MLT_ALGORITHM` for `MLT_ALGORITHM_PATH`.
    pub c_prefix: &'static str,
}

impl Choices {
    /// The C constant of `name`: `MLT_ALGORITHM_PATH_SPACE_MLT` for `path-space-mlt`.
    pub fn c_constant(&self, name: &str) -> String {
        format!(
            "{}_{}",
            self.c_prefix,
            name.replace('-', "_").to_uppercase()
        )
    }
}

/// A parameter's value, as a front end passes it by name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// Any integer: one outside the parameter's type is refused with its rule.
    Int(i128),
    Float(f64),
    Bool(bool),
    Choice(&'static str),
    Vec3([f32; 3]),
    Floats([f32; 4]),
    Texture(Option<TextureRef>),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Int(v) => write!(f, "{v}"),
            Value::Float(v) => write!(f, "{v}"),
            Value::Bool(v) => write!(f, "{v}"),
            Value::Choice(v) => write!(f, "{v}"),
            Value::Vec3([a, b, c]) => write!(f, "{a},{b},{c}"),
            Value::Floats([a, b, c, d]) => write!(f, "{a},{b},{c},{d}"),
            Value::Texture(None) => write!(f, "none"),
            Value::Texture(Some(t)) => write!(f, "texture {}", t.texture),
        }
    }
}

/// The values a numeric parameter accepts: `[min, max]` (or `(min, max]`), plus `off`, a
/// value outside it with a meaning of its own (0: "automatic", "no limit", "no filter").
/// NaN and infinities are never inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub min: f64,
    pub max: f64,
    /// `min` itself is outside.
    pub min_exclusive: bool,
    pub off: Option<f64>,
}

impl Range {
    /// `[0, 1]`, a fraction or probability; its rule is [`in_unit_interval`].
    pub const UNIT: Range = Range::closed(0.0, 1.0);

    /// `[min, max]`.
    pub const fn closed(min: f64, max: f64) -> Range {
        Range {
            min,
            max,
            min_exclusive: false,
            off: None,
        }
    }
    /// `(min, max]`.
    pub const fn above(min: f64, max: f64) -> Range {
        Range {
            min_exclusive: true,
            ..Range::closed(min, max)
        }
    }
    /// The range, plus `off`.
    pub const fn or(self, off: f64) -> Range {
        Range {
            off: Some(off),
            ..self
        }
    }
    pub fn contains(&self, x: f64) -> bool {
        let above_min = if self.min_exclusive {
            x > self.min
        } else {
            x >= self.min
        };
        self.off == Some(x) || (above_min && x <= self.max)
    }
}

/// What an out-of-range value's message says after `"<prefix>.<name> is <value>; "`, given
/// the whole struct (a limit may depend on another parameter).
pub type Rule<S> = fn(&S) -> String;

/// The rule of [`Range::UNIT`].
pub fn in_unit_interval<S>(_: &S) -> String {
    "it must be in [0, 1]".into()
}

/// What is known of one parameter of the struct `S`.
pub struct Parameter<S> {
    /// The field's name: the C field, C++ member, Python keyword and `set`/`get` name.
    pub name: &'static str,
    pub kind: Kind,
    /// One line, for `--help`, the docs table and the headers.
    pub doc: &'static str,
    /// The command-line flag, without `--`; `None` for a material's parameters, which the
    /// command line sets by name (`--material NAME=VALUE`).
    pub flag: Option<&'static str>,
    pub default: fn() -> Value,
    /// The values it accepts; `None`: every value of its kind.
    pub range: Option<Range>,
    pub rule: Option<Rule<S>>,
}

impl<S> Parameter<S> {
    /// A value of its kind outside its range, if it has one: what tests give every front
    /// end to see that each refuses it with the same message, and the fuzz generator's
    /// mistakes.
    pub fn outside_value(&self) -> Option<Value> {
        let range = self.range?;
        let is_f32 = matches!(self.kind, Kind::F32 | Kind::F32x3 | Kind::F32x4);
        let above = match self.kind {
            Kind::U32 | Kind::U64 => range.max + 1.0,
            _ => range.max * 2.0,
        };
        let representable = !is_f32 || above <= f32::MAX as f64;
        let below = range.min - 1.0;
        let bad = if range.min_exclusive {
            range.min
        } else if range.min >= 1.0 && range.off != Some(below) {
            below
        } else if representable {
            above
        } else {
            below
        };
        Some(match self.kind {
            Kind::U32 | Kind::U64 => Value::Int(bad as i128),
            Kind::F32 | Kind::F64 => Value::Float(bad),
            // The first component outside, the others their defaults.
            Kind::F32x3 => match (self.default)() {
                Value::Vec3([_, b, c]) => Value::Vec3([bad as f32, b, c]),
                _ => Value::Vec3([bad as f32; 3]),
            },
            Kind::F32x4 => match (self.default)() {
                Value::Floats([_, b, c, d]) => Value::Floats([bad as f32, b, c, d]),
                _ => Value::Floats([bad as f32; 4]),
            },
            Kind::Bool | Kind::Choice(_) | Kind::Texture => return None,
        })
    }
}

/// A struct made by `declare_parameters!`.
pub trait Parameters: Default + Sized + 'static {
    /// What messages name the struct by: `settings` in `settings.width is 0; …` (a
    /// struct that is one of many, a material, is named by its place instead when it is
    /// validated: `desc.materials[2]`).
    const PREFIX: &'static str;
    /// Every parameter, in declaration order (the C struct's field order).
    fn parameters() -> &'static [Parameter<Self>];
    /// The value of the parameter `name`, or `None` if there is none of that name.
    fn get(&self, name: &str) -> Option<Value>;
    /// Sets the parameter `name`: an unknown name, a value of another kind or an integer
    /// its type cannot hold is refused with a message. The range is checked later, by the
    /// struct's validation.
    fn set(&mut self, name: &str, value: Value) -> Result<()>;
    /// The parameter called `name`.
    fn parameter(name: &str) -> Option<&'static Parameter<Self>> {
        Self::parameters().iter().find(|p| p.name == name)
    }
}

/// Why a [`Value`] is not one of a type.
#[doc(hidden)]
pub enum Unfit {
    Kind,
    /// An integer outside the type.
    Domain,
}

/// A Rust type a parameter may have.
pub trait ParameterType: Copy {
    const KIND: Kind;
    fn to_value(self) -> Value;
    #[doc(hidden)]
    fn from_value(value: Value) -> std::result::Result<Self, Unfit>;
    /// The first value outside `range`, as messages print it, after the suffix that names
    /// it within the field (`[1]`, `.y`; empty for a single value).
    fn outside(&self, range: &Range) -> Option<(String, String)> {
        self.first(|x| !range.contains(x))
    }
    /// The first value that is not a finite number (NaN, an infinity), as `outside`.
    fn non_finite(&self) -> Option<(String, String)> {
        self.first(|x| !x.is_finite())
    }
    #[doc(hidden)]
    /// The first of the numbers the value holds for which `bad` is true, as `outside`.
    fn first(&self, bad: impl Fn(f64) -> bool) -> Option<(String, String)>;
    /// The texture, for a texture slot that holds one.
    #[doc(hidden)]
    #[inline(always)]
    fn texture(&self) -> Option<TextureRef> {
        None
    }
    /// The slot's texture or none, for a texture slot.
    #[doc(hidden)]
    fn texture_slot(&self) -> Option<Option<TextureRef>> {
        None
    }
    /// The slot, for a texture slot (holding a texture or not).
    #[doc(hidden)]
    fn texture_slot_mut(&mut self) -> Option<&mut Option<TextureRef>> {
        None
    }
}

macro_rules! integer_parameter {
    ($($ty:ty => $kind:ident),*) => {$(
        impl ParameterType for $ty {
            const KIND: Kind = Kind::$kind;
            fn to_value(self) -> Value {
                Value::Int(self as i128)
            }
            fn from_value(value: Value) -> std::result::Result<Self, Unfit> {
                match value {
                    Value::Int(v) => <$ty>::try_from(v).map_err(|_| Unfit::Domain),
                    _ => Err(Unfit::Kind),
                }
            }
            fn first(&self, bad: impl Fn(f64) -> bool) -> Option<(String, String)> {
                bad(*self as f64).then(|| (String::new(), self.to_string()))
            }
        }
    )*};
}
integer_parameter!(u32 => U32, u64 => U64);

macro_rules! float_parameter {
    ($($ty:ty => $kind:ident),*) => {$(
        impl ParameterType for $ty {
            const KIND: Kind = Kind::$kind;
            fn to_value(self) -> Value {
                Value::Float(self as f64)
            }
            fn from_value(value: Value) -> std::result::Result<Self, Unfit> {
                match value {
                    Value::Float(v) => Ok(v as $ty),
                    Value::Int(v) => Ok(v as $ty),
                    _ => Err(Unfit::Kind),
                }
            }
            fn first(&self, bad: impl Fn(f64) -> bool) -> Option<(String, String)> {
                bad(*self as f64).then(|| (String::new(), self.to_string()))
            }
        }
    )*};
}
float_parameter!(f32 => F32, f64 => F64);

impl ParameterType for bool {
    const KIND: Kind = Kind::Bool;
    fn to_value(self) -> Value {
        Value::Bool(self)
    }
    fn from_value(value: Value) -> std::result::Result<Self, Unfit> {
        match value {
            Value::Bool(v) => Ok(v),
            _ => Err(Unfit::Kind),
        }
    }
    fn first(&self, _: impl Fn(f64) -> bool) -> Option<(String, String)> {
        None
    }
}

impl ParameterType for [f32; 3] {
    const KIND: Kind = Kind::F32x3;
    fn to_value(self) -> Value {
        Value::Vec3(self)
    }
    fn from_value(value: Value) -> std::result::Result<Self, Unfit> {
        match value {
            Value::Vec3(v) => Ok(v),
            _ => Err(Unfit::Kind),
        }
    }
    /// Components are named `.x`, `.y`, `.z`, as the C API's vectors.
    fn first(&self, bad: impl Fn(f64) -> bool) -> Option<(String, String)> {
        ["x", "y", "z"]
            .iter()
            .zip(self)
            .find(|(_, w)| bad(**w as f64))
            .map(|(axis, w)| (format!(".{axis}"), w.to_string()))
    }
}

impl ParameterType for Option<TextureRef> {
    const KIND: Kind = Kind::Texture;
    fn to_value(self) -> Value {
        Value::Texture(self)
    }
    fn from_value(value: Value) -> std::result::Result<Self, Unfit> {
        match value {
            Value::Texture(v) => Ok(v),
            _ => Err(Unfit::Kind),
        }
    }
    /// The slot's index and transform are checked by the material, which knows the
    /// textures.
    fn first(&self, _: impl Fn(f64) -> bool) -> Option<(String, String)> {
        None
    }
    #[inline(always)]
    fn texture(&self) -> Option<TextureRef> {
        *self
    }
    fn texture_slot(&self) -> Option<Option<TextureRef>> {
        Some(*self)
    }
    fn texture_slot_mut(&mut self) -> Option<&mut Option<TextureRef>> {
        Some(self)
    }
}

impl ParameterType for [f32; 4] {
    const KIND: Kind = Kind::F32x4;
    fn to_value(self) -> Value {
        Value::Floats(self)
    }
    fn from_value(value: Value) -> std::result::Result<Self, Unfit> {
        match value {
            Value::Floats(v) => Ok(v),
            _ => Err(Unfit::Kind),
        }
    }
    fn first(&self, bad: impl Fn(f64) -> bool) -> Option<(String, String)> {
        self.iter()
            .enumerate()
            .find(|(_, w)| bad(**w as f64))
            .map(|(i, w)| (format!("[{i}]"), w.to_string()))
    }
}

/// A parameter whose value is one of a few names (an enum): `NAMES[i]` is `ALL[i]`'s.
pub trait ChoiceParameter: Copy + PartialEq + 'static {
    const NAMES: &'static [&'static str];
    /// The values, in the order of their C constants (0, 1, …).
    const ALL: &'static [Self];
    /// [`Choices::type_name`].
    const TYPE_NAME: &'static str;
    /// [`Choices::c_prefix`].
    const C_PREFIX: &'static str;
    const CHOICES: Choices = Choices {
        names: Self::NAMES,
        type_name: Self::TYPE_NAME,
        c_prefix: Self::C_PREFIX,
    };
    fn name(self) -> &'static str {
        let i = Self::ALL.iter().position(|&v| v == self);
        Self::NAMES[i.expect("ALL holds every value")]
    }
    /// The value of `name` (case, and `-` against `_`, do not matter).
    fn from_name(name: &str) -> Option<Self> {
        let canonical = |c: char| match c {
            '_' => '-',
            c => c.to_ascii_lowercase(),
        };
        Self::NAMES
            .iter()
            .position(|n| n.len() == name.len() && n.chars().eq(name.chars().map(canonical)))
            .map(|i| Self::ALL[i])
    }
}

impl<T: ChoiceParameter> ParameterType for T {
    const KIND: Kind = Kind::Choice(&T::CHOICES);
    fn to_value(self) -> Value {
        Value::Choice(self.name())
    }
    fn from_value(value: Value) -> std::result::Result<Self, Unfit> {
        match value {
            Value::Choice(name) => T::from_name(name).ok_or(Unfit::Domain),
            _ => Err(Unfit::Kind),
        }
    }
    fn first(&self, _: impl Fn(f64) -> bool) -> Option<(String, String)> {
        None
    }
}

/// Checks one field, with the message every front end shows: every number must be finite,
/// then within the field's range, if it has one.
#[doc(hidden)]
pub fn check<S, T: ParameterType>(
    settings: &S,
    prefix: &str,
    name: &str,
    value: T,
    range: Option<(Range, Rule<S>)>,
) -> Result<()> {
    if let Some((part, shown)) = value.non_finite() {
        return Err(Error::invalid(format!(
            "{prefix}.{name}{part} is {shown}; it must be a finite number"
        )));
    }
    match range.and_then(|(range, rule)| Some((value.outside(&range)?, rule))) {
        None => Ok(()),
        Some(((part, shown), rule)) => Err(Error::invalid(format!(
            "{prefix}.{name}{part} is {shown}; {}",
            rule(settings)
        ))),
    }
}

/// Converts a value given by name to the field's type, or the message that refuses it.
#[doc(hidden)]
pub fn convert<S, T: ParameterType>(
    settings: &S,
    prefix: &str,
    name: &str,
    value: Value,
    rule: Option<Rule<S>>,
) -> Result<T> {
    T::from_value(value).map_err(|unfit| match (unfit, rule) {
        (Unfit::Domain, Some(rule)) => {
            Error::invalid(format!("{prefix}.{name} is {value}; {}", rule(settings)))
        }
        (Unfit::Domain, None) => match T::KIND {
            Kind::Choice(choices) => Error::invalid(format!(
                "{prefix}.{name} is {value:?}; expected one of {}",
                choices
                    .names
                    .iter()
                    .map(|n| format!("{n:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
            _ => Error::invalid(format!("{prefix}.{name} is {value}; out of its type")),
        },
        (Unfit::Kind, _) => Error::invalid(format!(
            "{prefix}.{name} is {value}; it takes {}",
            kind_noun(T::KIND)
        )),
    })
}

/// "an integer", "a number", … for messages.
pub fn kind_noun(kind: Kind) -> &'static str {
    match kind {
        Kind::U32 | Kind::U64 => "an integer",
        Kind::F32 | Kind::F64 => "a number",
        Kind::Bool => "a boolean",
        Kind::Choice(_) => "one of its names",
        Kind::F32x3 => "three numbers",
        Kind::F32x4 => "four numbers",
        Kind::Texture => "a texture slot",
    }
}

/// Declares a struct of parameters (see the module's documentation). Each field:
///
/// ```text
/// /// Rust documentation of the field.
/// name: Type = default {
///     doc: "One line.",
///     // Optional: the command-line flag.
///     flag: "command-line-flag",
///     // Optional, for numbers: the values it accepts and the message's rule.
///     range: Range::closed(1.0, 8.0),
///     rule: |settings| format!("it must be between 1 and 8"),
/// },
/// ```
macro_rules! declare_parameters {
    (
        $(#[$struct_attr:meta])*
        pub struct $Struct:ident in $prefix:literal {
            $(
                $(#[$attr:meta])*
                $name:ident: $ty:ty = $default:expr => {
                    doc: $doc:literal,
                    $(flag: $flag:literal,)?
                    $(range: $range:expr, rule: $rule:expr,)?
                }
            ),* $(,)?
        }
    ) => {
        $(#[$struct_attr])*
        pub struct $Struct {
            $( $(#[$attr])* pub $name: $ty, )*
        }

        impl Default for $Struct {
            fn default() -> Self {
                $Struct { $( $name: $default, )* }
            }
        }

        impl $Struct {
            /// Checks every field, in declaration order: its numbers finite and within its
            /// declared range. Messages name the struct `prefix`.
            fn check_ranges(&self, prefix: &str) -> $crate::error::Result<()> {
                $({
                    #[allow(unused_variables)]
                    let range: Option<($crate::params::Range, $crate::params::Rule<Self>)> = None;
                    $( let range: Option<($crate::params::Range, $crate::params::Rule<Self>)> =
                        Some(($range, $rule)); )?
                    $crate::params::check(self, prefix, stringify!($name), self.$name, range)?;
                })*
                Ok(())
            }

            /// Whether any texture slot holds a texture (a test per slot: hot code asks).
            #[allow(dead_code)]
            #[inline(always)]
            pub(crate) fn any_texture(&self) -> bool {
                false $(|| $crate::params::ParameterType::texture(&self.$name).is_some())*
            }

            /// The texture slots that hold a texture, with their names, in declaration order.
            #[allow(dead_code)]
            #[inline(always)]
            pub(crate) fn textures(
                &self,
            ) -> impl Iterator<Item = (&'static str, $crate::texture::TextureRef)> {
                [$(
                    (stringify!($name), $crate::params::ParameterType::texture(&self.$name)),
                )*]
                .into_iter()
                .filter_map(|(name, texture)| Some((name, texture?)))
            }

            /// Every texture slot, holding a texture or not, with its name, in declaration
            /// order (the order of the C material's `texcoord1_slots` bits).
            #[allow(dead_code)]
            pub(crate) fn texture_slots(
                &self,
            ) -> impl Iterator<Item = (&'static str, Option<$crate::texture::TextureRef>)> {
                [$(
                    (stringify!($name), $crate::params::ParameterType::texture_slot(&self.$name)),
                )*]
                .into_iter()
                .filter_map(|(name, slot)| Some((name, slot?)))
            }

            /// [`Self::texture_slots`], to change.
            #[allow(dead_code)]
            pub(crate) fn texture_slots_mut(
                &mut self,
            ) -> impl Iterator<Item = (&'static str, &mut Option<$crate::texture::TextureRef>)> {
                [$(
                    (stringify!($name), $crate::params::ParameterType::texture_slot_mut(&mut self.$name)),
                )*]
                .into_iter()
                .filter_map(|(name, slot)| Some((name, slot?)))
            }
        }

        impl $crate::params::Parameters for $Struct {
            const PREFIX: &'static str = $prefix;
            fn parameters() -> &'static [$crate::params::Parameter<Self>] {
                static PARAMETERS: &[$crate::params::Parameter<$Struct>] = &[$(
                    $crate::params::Parameter {
                        name: stringify!($name),
                        kind: <$ty as $crate::params::ParameterType>::KIND,
                        doc: $doc,
                        flag: {
                            #[allow(unused_variables)]
                            let flag: Option<&'static str> = None;
                            $( let flag = Some($flag); )?
                            flag
                        },
                        default: || {
                            <$ty as $crate::params::ParameterType>::to_value($default)
                        },
                        range: {
                            #[allow(unused_variables)]
                            let range: Option<$crate::params::Range> = None;
                            $( let range = Some($range); )?
                            range
                        },
                        rule: {
                            #[allow(unused_variables)]
                            let rule: Option<$crate::params::Rule<$Struct>> = None;
                            $( let rule: Option<$crate::params::Rule<$Struct>> = Some($rule); )?
                            rule
                        },
                    },
                )*];
                PARAMETERS
            }
            fn get(&self, name: &str) -> Option<$crate::params::Value> {
                match name {
                    $( stringify!($name) => {
                        Some($crate::params::ParameterType::to_value(self.$name))
                    } )*
                    _ => None,
                }
            }
            fn set(&mut self, name: &str, value: $crate::params::Value) -> $crate::error::Result<()> {
                match name {
                    $( stringify!($name) => {
                        let rule = <Self as $crate::params::Parameters>::parameter(name)
                            .and_then(|p| p.rule);
                        self.$name = $crate::params::convert(self, $prefix, name, value, rule)?;
                        Ok(())
                    } )*
                    _ => Err($crate::error::Error::invalid(format!(
                        "{} has no parameter {name:?}", $prefix
                    ))),
                }
            }
        }
    };
}
pub(crate) use declare_parameters;
