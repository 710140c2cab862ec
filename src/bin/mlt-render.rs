//! `mlt-render`: render an OBJ or glTF scene to PFM, OpenEXR or PNG.
//!
//! Errors print one line, `mlt-render: <message>`, to stderr and exit with status 1.

use clap::builder::{PossibleValuesParser, TypedValueParser, ValueParser};
use clap::parser::ValueSource;
use clap::{Arg, ArgAction, ArgMatches, Parser, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use mlt::io::{CameraFile, ImageFormat};
use mlt::params::{ChoiceParameter, Kind, Parameters, Value};
use mlt::{
    EnvironmentDesc, LightsDesc, Material, RenderSettings, RenderStats, Scene, StopReason, SunDesc,
};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// The render settings' flags, made from their declarations (`mlt::params`): each
/// setting's flag, help line and default come from `src/render/settings.rs`.
#[derive(Clone, Debug)]
struct SettingsArgs {
    /// The settings given on the command line, by name; the others keep their defaults.
    given: Vec<(&'static str, Value)>,
}

/// Settings whose default is the camera's, not the declared one.
const FROM_CAMERA: [&str; 2] = ["width", "height"];

/// `value` as a flag takes it.
fn flag_text(kind: Kind, value: Value) -> String {
    match (kind, value) {
        (Kind::F32, Value::Float(v)) => (v as f32).to_string(),
        (_, v) => v.to_string(),
    }
}

/// Parses a flag's text into a value of `kind` (the range is checked with the others).
fn parse_value(kind: Kind, text: &str) -> Result<Value, String> {
    let text = text.trim();
    let float = |t: &str| t.trim().parse::<f32>().map_err(|e| format!("{t:?}: {e}"));
    let floats = |n: usize| -> Result<Vec<f32>, String> {
        let values: Vec<f32> = text.split(',').map(float).collect::<Result<_, _>>()?;
        if values.len() == n {
            Ok(values)
        } else {
            Err(format!("{n} numbers are needed, not {}", values.len()))
        }
    };
    let integer = |t: &str| t.parse::<i128>().map_err(|e| format!("{t:?}: {e}"));
    match kind {
        Kind::U32 | Kind::U64 => integer(text).map(Value::Int),
        Kind::F32 => float(text).map(|v| Value::Float(v.into())),
        Kind::F64 => text
            .parse::<f64>()
            .map(Value::Float)
            .map_err(|e| format!("{text:?}: {e}")),
        Kind::Bool => match text {
            "true" | "1" => Ok(Value::Bool(true)),
            "false" | "0" => Ok(Value::Bool(false)),
            _ => Err(format!("{text:?}: expected true or false")),
        },
        Kind::Choice(choices) => {
            let canonical = |c: char| match c {
                '_' => '-',
                c => c.to_ascii_lowercase(),
            };
            let given: String = text.chars().map(canonical).collect();
            choices
                .names
                .iter()
                .find(|&&n| n == given)
                .map(|&n| Value::Choice(n))
                .ok_or_else(|| format!("{text:?}: expected one of {}", choices.names.join(", ")))
        }
        Kind::F32x3 => floats(3).map(|v| Value::Vec3([v[0], v[1], v[2]])),
        Kind::F32x4 => floats(4).map(|v| Value::Floats([v[0], v[1], v[2], v[3]])),
        Kind::Texture => match text {
            "none" => Ok(Value::Texture(None)),
            _ => u32::try_from(integer(text)?)
                .map(|i| Value::Texture(Some(mlt::TextureRef::new(i))))
                .map_err(|_| format!("{text:?}: expected none or a texture's index")),
        },
    }
}

/// `--material NAME=VALUE`: a declared material parameter and its value.
fn parse_material_parameter(text: &str) -> Result<(&'static str, Value), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("{text:?}: expected NAME=VALUE"))?;
    let p = Material::parameter(name.trim()).ok_or_else(|| {
        let names: Vec<&str> = Material::parameters().iter().map(|p| p.name).collect();
        format!(
            "{name:?} is not a material parameter; they are {}",
            names.join(", ")
        )
    })?;
    Ok((p.name, parse_value(p.kind, value)?))
}

/// `--material`'s long help: every declared parameter with its default.
fn material_help() -> String {
    let mut help = String::from(
        "Set a parameter of every material of the scene, after the file's values (a clay \
         render: --material kind=diffuse --material color=0.8,0.8,0.8); repeatable. A texture \
         slot takes none or a texture's index. The parameters, with mlt's defaults:",
    );
    for p in Material::parameters() {
        help += &format!(
            "\n  {}  {} [default: {}]",
            p.name,
            p.doc,
            flag_text(p.kind, (p.default)())
        );
    }
    help
}

impl clap::Args for SettingsArgs {
    fn augment_args(mut command: clap::Command) -> clap::Command {
        for p in RenderSettings::parameters() {
            let flag = p.flag.expect("every setting has a flag");
            let mut arg = Arg::new(p.name).long(flag).help(p.doc);
            let full_name = p.name.replace('_', "-");
            if full_name != flag {
                arg = arg.visible_alias(full_name);
            }
            let kind = p.kind;
            arg = match kind {
                Kind::Bool => arg.action(ArgAction::SetTrue),
                Kind::Choice(&mlt::params::Choices { names, .. }) => arg.value_parser(
                    PossibleValuesParser::new(names.iter().copied()).map(move |name| {
                        Value::Choice(names.iter().find(|&&n| n == name).expect("a choice"))
                    }),
                ),
                _ => arg
                    .allow_hyphen_values(true)
                    .value_name(match kind {
                        Kind::U32 | Kind::U64 => "N",
                        Kind::F32x4 => "B,L,C,M",
                        _ => "X",
                    })
                    .value_parser(ValueParser::new(move |text: &str| parse_value(kind, text))),
            };
            if !FROM_CAMERA.contains(&p.name) && kind != Kind::Bool {
                arg = arg.default_value(flag_text(kind, (p.default)()));
            }
            if FROM_CAMERA.contains(&p.name) {
                arg = arg.help(format!("{} Default: the camera's.", p.doc));
            }
            command = command.arg(arg);
        }
        command
    }
    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        Self::augment_args(command)
    }
}

impl clap::FromArgMatches for SettingsArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let given = RenderSettings::parameters()
            .iter()
            .filter(|p| matches.value_source(p.name) == Some(ValueSource::CommandLine))
            .map(|p| {
                let value = match p.kind {
                    Kind::Bool => Value::Bool(matches.get_flag(p.name)),
                    _ => *matches.get_one::<Value>(p.name).expect("a parsed value"),
                };
                (p.name, value)
            })
            .collect();
        Ok(SettingsArgs { given })
    }
    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}

/// Three comma-separated numbers: a colour or a direction.
#[derive(Clone, Copy, Debug)]
struct Vec3Arg([f32; 3]);

/// Parses `N,N,N` (or `N,N,N,N` when `allow_fourth`), each number finite.
fn parse_numbers(text: &str, allow_fourth: bool) -> Result<Vec<f32>, String> {
    let values: Vec<f32> = text
        .split(',')
        .map(|v| {
            let v = v.trim();
            match v.parse::<f32>() {
                Ok(x) if x.is_finite() => Ok(x),
                Ok(x) => Err(format!("{x} is not a finite number")),
                Err(e) => Err(format!("{v:?}: {e}")),
            }
        })
        .collect::<Result<_, _>>()?;
    let expected = if allow_fourth { "3 or 4" } else { "3" };
    if values.len() == 3 || (allow_fourth && values.len() == 4) {
        Ok(values)
    } else {
        Err(format!(
            "{expected} comma-separated numbers are needed, not {}",
            values.len()
        ))
    }
}

/// A linear RGB radiance or irradiance: three numbers, each >= 0.
fn parse_rgb(text: &str) -> Result<Vec3Arg, String> {
    let v = parse_numbers(text, false)?;
    if let Some(x) = v.iter().find(|x| **x < 0.0) {
        return Err(format!("{x} is negative; light must be >= 0"));
    }
    Ok(Vec3Arg([v[0], v[1], v[2]]))
}

/// A direction, then an optional angular radius in degrees (the sun's).
#[derive(Clone, Copy, Debug)]
struct SunArg {
    direction: [f32; 3],
    angular_radius_degrees: Option<f32>,
}

fn parse_sun(text: &str) -> Result<SunArg, String> {
    let v = parse_numbers(text, true)?;
    let direction = [v[0], v[1], v[2]];
    if direction == [0.0; 3] {
        return Err("the direction 0,0,0 has no direction".into());
    }
    let angular_radius_degrees = v.get(3).copied();
    if let Some(r) = angular_radius_degrees
        && !(0.0..=45.0).contains(&r)
    {
        return Err(format!(
            "the angular radius {r} must be in [0, 45] degrees (0: a delta direction)"
        ));
    }
    Ok(SunArg {
        direction,
        angular_radius_degrees,
    })
}

/// A finite number >= 0.
fn parse_scale(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        Ok(x) => Err(format!("{x} must be a finite number >= 0")),
        Err(e) => Err(format!("{text:?}: {e}")),
    }
}

/// A finite number.
fn parse_finite(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(x) => Err(format!("{x} is not a finite number")),
        Err(e) => Err(format!("{text:?}: {e}")),
    }
}

/// The real sun's angular radius, in degrees: `--sun`'s when it gives none.
const SUN_ANGULAR_RADIUS_DEGREES: f32 = 0.27;

#[derive(Clone, Copy, Debug, ValueEnum)]
enum BackendArg {
    /// The built-in BVH.
    Bvh,
    /// Intel Embree (only in builds with the `embree` feature).
    Embree,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum BuildQualityArg {
    /// The quickest build, slower rays: for scenes rebuilt often.
    Fast,
    /// Between the two.
    Medium,
    /// The acceleration structure that renders fastest.
    High,
}

/// Render a scene with mlt.
///
/// SCENE is a Wavefront OBJ (with its MTL; the camera from NAME.camera.json beside it) or a
/// glTF 2.0 file (.gltf/.glb; the camera from its first perspective camera). The image is
/// linear RGB; .png output is clamped to [0, 1] and sRGB-encoded.
#[derive(Debug, Parser)]
#[command(name = "mlt-render", version)]
struct Args {
    /// Scene file: .obj, .gltf or .glb.
    scene: PathBuf,
    /// Camera JSON (eye, target, up, fov_y_deg, width, height); overrides the scene's camera.
    #[arg(long, value_name = "FILE.json")]
    camera: Option<PathBuf>,
    /// glTF: render the material variant of this name (KHR_materials_variants) instead of
    /// the default materials.
    #[arg(long, value_name = "NAME")]
    variant: Option<String>,
    #[command(flatten)]
    settings: SettingsArgs,
    /// Compensate rough metals (glTF metallic-roughness) for the light that bounces between
    /// microfacets more than once, which glTF's model loses (Kulla-Conty): a white metal
    /// reflects all the light at every roughness instead of 31% at roughness 1.
    #[arg(long)]
    energy_compensation: bool,
    /// Make every dielectric (glass, and transmissive glTF materials) without a dispersion
    /// of its own dispersive with this Abbe number (crown glass ~60, flint ~36, lower is
    /// stronger). Seen in --spectral renders only.
    #[arg(long, value_name = "V")]
    abbe_number: Option<f32>,
    /// Set a material parameter on every material (see the long help, --help).
    #[arg(long = "material", value_name = "NAME=VALUE", value_parser = parse_material_parameter, allow_hyphen_values = true)]
    material: Vec<(&'static str, Value)>,
    /// Metropolis and ERPT: filter the image's blotchy noise after the render (non-local
    /// means guided by variances measured from partial images; keeps the total), with 8
    /// partial images unless --filter-buffers says otherwise.
    #[arg(long)]
    filter: bool,
    /// Ray-intersection backend.
    #[arg(long, value_enum, default_value = "bvh")]
    backend: BackendArg,
    /// How much work the acceleration structure's build spends for faster rays.
    #[arg(long, value_enum, default_value = "high")]
    build_quality: BuildQualityArg,
    /// Environment map lighting the scene from infinitely far away: an equirectangular
    /// (latitude-longitude) .hdr or .exr of linear radiance, +Y up, its centre looking
    /// along +Z.
    #[arg(long, value_name = "FILE.{exr,hdr}", conflicts_with = "background")]
    env: Option<PathBuf>,
    /// Multiplies the environment (--env or --background).
    #[arg(long, value_name = "S", default_value_t = 1.0, value_parser = parse_scale, allow_hyphen_values = true)]
    env_scale: f32,
    /// Turns the environment about +Y by this many degrees (counter-clockwise seen from
    /// above).
    #[arg(long, value_name = "DEG", default_value_t = 0.0, value_parser = parse_finite, allow_hyphen_values = true)]
    env_rotate: f32,
    /// A constant environment of this linear RGB radiance (instead of --env).
    #[arg(long, value_name = "R,G,B", value_parser = parse_rgb, allow_hyphen_values = true)]
    background: Option<Vec3Arg>,
    /// The sun: the direction towards it and its angular radius in degrees (0 to 45; 0 is a
    /// delta direction, the default 0.27 the real sun's). Needs --sun-irradiance or
    /// --sun-radiance.
    #[arg(long, value_name = "DIR_X,DIR_Y,DIR_Z[,RADIUS_DEG]", value_parser = parse_sun, allow_hyphen_values = true)]
    sun: Option<SunArg>,
    /// With --sun: its linear RGB irradiance on a plane facing it.
    #[arg(long, value_name = "R,G,B", value_parser = parse_rgb, requires = "sun", conflicts_with = "sun_radiance", allow_hyphen_values = true)]
    sun_irradiance: Option<Vec3Arg>,
    /// With --sun: the linear RGB radiance of its disc (needs a radius > 0).
    #[arg(long, value_name = "R,G,B", value_parser = parse_rgb, requires = "sun", allow_hyphen_values = true)]
    sun_radiance: Option<Vec3Arg>,
    /// Output image: .pfm, .exr or .png.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

fn main() -> ExitCode {
    use clap::{CommandFactory, FromArgMatches};
    let command = Args::command().mut_arg("material", |arg| arg.long_help(material_help()));
    let args = match command
        .try_get_matches()
        .and_then(|matches| Args::from_arg_matches(&matches))
    {
        Ok(args) => args,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            // clap's message is several paragraphs (problem, usage, hint): keep the first,
            // on one line, without "error: ".
            let text = e.render().to_string();
            let first: Vec<&str> = text
                .lines()
                .map(str::trim)
                .take_while(|line| !line.is_empty())
                .collect();
            let first = first.join(" ");
            let first = first.strip_prefix("error: ").unwrap_or(&first);
            eprintln!("mlt-render: {first} (see mlt-render --help)");
            return ExitCode::FAILURE;
        }
    };
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            // One line, whatever the message contains.
            let line = message.replace('\n', " ");
            eprintln!("mlt-render: {line}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &Args) -> Result<(), String> {
    // Reject an unusable output path before spending time on loading and rendering.
    ImageFormat::from_path(&args.out).map_err(|e| e.to_string())?;
    check_output_directory(&args.out)?;

    let load_start = Instant::now();
    let mut data = mlt::io::load_scene_variant(&args.scene, args.variant.as_deref())
        .map_err(|e| e.to_string())?;
    data.override_materials(args.energy_compensation, args.abbe_number);
    for material in &mut data.materials {
        for &(name, value) in &args.material {
            material.set(name, value).map_err(|e| e.message)?;
        }
    }
    let framed = data.camera.is_none() && args.camera.is_none();
    let camera_file = match &args.camera {
        Some(path) => mlt::io::load_camera_json(path).map_err(|e| e.to_string())?,
        None => data.camera.unwrap_or_else(|| {
            let (min, max) = data.bounds();
            CameraFile::framing(min, max)
        }),
    };
    if framed {
        eprintln!(
            "mlt-render: {} has no camera; framing its bounds with this one (save it as a file, edit it and pass it with --camera FILE.json):\n{}",
            args.scene.display(),
            camera_file.to_json()
        );
    }
    let backend = match args.backend {
        BackendArg::Bvh => mlt::Backend::Bvh,
        BackendArg::Embree => mlt::Backend::Embree,
    };
    let sun = sun(args)?;
    let environment = match (&args.env, args.background) {
        (Some(path), _) => Some(mlt::io::load_environment(path).map_err(|e| e.to_string())?),
        (None, Some(Vec3Arg(rgb))) => Some((rgb.to_vec(), 1, 1)),
        (None, None) => None,
    };
    let mut desc = data.desc(backend);
    desc.build_quality = match args.build_quality {
        BuildQualityArg::Fast => mlt::BuildQuality::Fast,
        BuildQualityArg::Medium => mlt::BuildQuality::Medium,
        BuildQualityArg::High => mlt::BuildQuality::High,
    };
    desc.lights.sun = sun;
    desc.lights.environment = environment
        .as_ref()
        .map(|(pixels, width, height)| EnvironmentDesc {
            pixels,
            width: *width,
            height: *height,
            rotation_degrees: args.env_rotate,
            scale: args.env_scale,
        });
    let lights = describe_lights(&desc.lights);
    let scene = Scene::new(&desc).map_err(|e| {
        format!(
            "cannot build the scene from {}: {}: {}",
            args.scene.display(),
            e.status.description(),
            data.describe_error(&e)
        )
    })?;
    let load_seconds = load_start.elapsed().as_secs_f64();

    let settings = settings(args, &camera_file)?;
    let mut rgb = vec![0.0f32; settings.output_len().map_err(|e| e.message)?];
    let bar = progress_bar();
    let mut on_progress = |fraction: f32| {
        bar.set_position((fraction.clamp(0.0, 1.0) * 1000.0) as u64);
        true
    };
    let result = mlt::render(
        &scene,
        &camera_file.camera,
        &settings,
        &mut rgb,
        Some(&mut on_progress),
    );
    bar.finish_and_clear();
    let stats = result.map_err(|e| format!("cannot render {}: {e}", args.scene.display()))?;

    mlt::io::write_image(&args.out, settings.width, settings.height, &rgb)
        .map_err(|e| e.to_string())?;
    print_summary(args, &scene, &lights, &settings, &stats, load_seconds);
    Ok(())
}

/// The sun of `--sun` with `--sun-irradiance` or `--sun-radiance`.
fn sun(args: &Args) -> Result<Option<SunDesc>, String> {
    let Some(sun) = args.sun else {
        return Ok(None);
    };
    let radius = sun
        .angular_radius_degrees
        .unwrap_or(SUN_ANGULAR_RADIUS_DEGREES);
    match (args.sun_irradiance, args.sun_radiance) {
        (Some(Vec3Arg(irradiance)), _) => Ok(Some(SunDesc {
            direction: sun.direction,
            angular_radius_degrees: radius,
            irradiance,
        })),
        (None, Some(Vec3Arg(radiance))) => {
            if radius == 0.0 {
                return Err(
                    "--sun-radiance needs a sun of angular radius > 0 (a delta sun has only an irradiance: use --sun-irradiance)".into(),
                );
            }
            Ok(Some(SunDesc::from_radiance(
                sun.direction,
                radius,
                radiance,
            )))
        }
        (None, None) => Err("--sun needs --sun-irradiance R,G,B or --sun-radiance R,G,B".into()),
    }
}

/// The lights besides emissive triangles, for the summary ("" if none).
fn describe_lights(lights: &LightsDesc) -> String {
    let mut parts = Vec::new();
    if let Some(e) = &lights.environment {
        parts.push(if e.width * e.height == 1 {
            "constant environment".to_owned()
        } else {
            format!("{} x {} environment", e.width, e.height)
        });
    }
    if let Some(sun) = &lights.sun {
        parts.push(format!("sun of {}°", sun.angular_radius_degrees));
    }
    if !lights.punctual.is_empty() {
        parts.push(format!("{} punctual", lights.punctual.len()));
    }
    parts.join(", ")
}

/// The settings of the command line: the camera's size, then every flag given.
fn settings(args: &Args, camera: &CameraFile) -> Result<RenderSettings, String> {
    let mut settings = RenderSettings {
        width: camera.width,
        height: camera.height,
        ..RenderSettings::default()
    };
    for &(name, value) in &args.settings.given {
        settings.set(name, value).map_err(|e| e.message)?;
    }
    let buffers_given = args
        .settings
        .given
        .iter()
        .any(|(n, _)| *n == "filter_buffers");
    if args.filter && !buffers_given {
        settings.filter_buffers = RenderSettings::DEFAULT_FILTER_BUFFERS;
    }
    Ok(settings)
}

fn check_output_directory(out: &Path) -> Result<(), String> {
    let directory = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => return Ok(()),
    };
    if directory.is_dir() {
        Ok(())
    } else {
        Err(format!(
            "cannot write image {}: directory {} does not exist",
            out.display(),
            directory.display()
        ))
    }
}

fn progress_bar() -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{wide_bar}] {percent:>3}% eta {eta}")
            .expect("the progress template is valid")
            .progress_chars("=> "),
    );
    bar
}

/// A line of the summary: the label in a column wide enough for every label.
fn row(label: &str, value: impl std::fmt::Display) {
    println!("  {label:<13} {value}");
}

fn print_summary(
    args: &Args,
    scene: &Scene,
    lights: &str,
    settings: &RenderSettings,
    stats: &RenderStats,
    load_seconds: f64,
) {
    let info = scene.info();
    let pixels = settings.width as f64 * settings.height as f64;
    let seconds = stats.seconds.max(1e-9);
    // A render asked for no sample or mutation count runs until its time limit: reaching it
    // is finishing, not stopping early.
    let planned_by_time = if settings.algorithm.is_metropolis() {
        settings.mutations_per_pixel == 0
    } else {
        settings.samples_per_pixel == 0
    };
    let stop = match stats.stop {
        StopReason::Completed => "completed".to_owned(),
        StopReason::Cancelled => "stopped early: cancelled".to_owned(),
        StopReason::TimeLimitReached if planned_by_time => format!(
            "completed at the time limit of {} s",
            settings.time_limit_seconds
        ),
        StopReason::TimeLimitReached => format!(
            "stopped early: time limit of {} s reached before the planned work",
            settings.time_limit_seconds
        ),
    };
    let algorithm = settings.algorithm.name();
    println!(
        "mlt-render: {} -> {} ({} x {}, {algorithm}, max depth {})",
        args.scene.display(),
        args.out.display(),
        settings.width,
        settings.height,
        settings.max_depth
    );
    row(
        "scene",
        format!(
            "{} triangles, {} emitters, {} backend, loaded in {:.3} s",
            info.triangle_count,
            info.emitter_count,
            format!("{:?}", args.backend).to_lowercase(),
            load_seconds
        ),
    );
    row(
        "acceleration",
        format!(
            "{} build in {:.3} s, {:.1} MB",
            format!("{:?}", info.build_quality).to_lowercase(),
            info.accel_build_seconds,
            info.accel_memory_bytes as f64 / 1e6
        ),
    );
    if !lights.is_empty() {
        row("lights", lights);
    }
    row("wall time", format!("{:.3} s", stats.seconds));
    row(
        "samples",
        format!(
            "{} ({:.2} per pixel)",
            stats.samples,
            stats.samples as f64 / pixels
        ),
    );
    row(
        "samples/s",
        format!("{:.3} M", stats.samples as f64 / seconds / 1e6),
    );
    if settings.algorithm.is_metropolis() || settings.algorithm == mlt::Algorithm::Erpt {
        row(
            "mutations",
            format!(
                "{} ({:.2} per pixel)",
                stats.mutations,
                stats.mutations as f64 / pixels
            ),
        );
        row(
            "mutations/s",
            format!("{:.3} M", stats.mutations as f64 / seconds / 1e6),
        );
    }
    row(
        "rays",
        format!(
            "{} ({:.3} Mrays/s)",
            stats.rays,
            stats.rays as f64 / seconds / 1e6
        ),
    );
    row("threads", stats.threads);
    let accepted = 100.0 * stats.accepted_mutations as f64 / stats.mutations.max(1) as f64;
    if settings.algorithm == mlt::Algorithm::Erpt {
        row(
            "erpt",
            format!(
                "e_d = {:.6}, {accepted:.1}% of mutations accepted",
                stats.normalization.value
            ),
        );
    } else if stats.normalization.value > 0.0 {
        let b = stats.normalization;
        row(
            "metropolis",
            format!(
                "b = {:.6} ± {:.2}% (from {} samples, the brightest {:.3}% of it), {accepted:.1}% of mutations accepted",
                b.value,
                100.0 * b.relative_error,
                b.samples,
                100.0 * b.largest_share,
            ),
        );
    }
    let counts = stats.mutation_counts;
    if counts.proposed.iter().any(|&n| n > 0) {
        for mutation in mlt::Mutation::ALL {
            let (proposed, accepted) = (
                counts.proposed[mutation as usize],
                counts.accepted[mutation as usize],
            );
            row(
                &format!("{mutation:?}").to_lowercase(),
                format!(
                    "{proposed} proposed, {:.1}% accepted, weight {:.3}",
                    100.0 * accepted as f64 / proposed.max(1) as f64,
                    stats.mutation_weights.0[mutation as usize]
                ),
            );
        }
    }
    if settings.filter_buffers > 0 {
        row(
            "filter",
            format!(
                "{} partial images, strength {}, radius {}: {:.1} pixels averaged per pixel, {:.2}% of the luminance moved (total kept)",
                settings.filter_buffers,
                settings.filter_strength,
                settings.filter_radius,
                stats.filter.mean_neighbours,
                100.0 * stats.filter.changed_fraction
            ),
        );
    }
    if stats.invalid_samples > 0 {
        row(
            "invalid",
            format!(
                "{} samples with non-finite radiance dropped",
                stats.invalid_samples
            ),
        );
    }
    row("status", stop);
}
