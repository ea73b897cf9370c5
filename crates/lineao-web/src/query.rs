//! The page's URL: `?url=FILE` or `?scene=NAME`, and the viewer's options as `lineao view`
//! takes them — `?compare=lineao,ssao&preset=paper&orbit=30,10,0.8` is
//! `lineao view --compare lineao,ssao --preset paper --orbit 30,10,0.8`. One typed settings
//! layer (`ViewArgs`) for the command line and the link, parsed by the same clap definitions,
//! so a link refuses what the command line refuses, with the same words.
//!
//! A key without a value is a flag (`?ortho&timings`). What a page cannot do is refused by
//! name: a positional file (use `url=`), `screenshot`, `frames` and `size` (the page is the
//! window), and object-space AO (CPU threads, see `lineao_cli::view::controls::WEB_LEAVES_OUT`).
//! `volume=` is an address, as `url=` is: the anatomy fetched beside the tractogram, its slices
//! where `slices=` puts them; and so are the files of `color=volume:ADDRESS` and
//! `color=tsf:ADDRESS`, fetched before the tractogram, whose values colour it.

use clap::Parser;
use lineao_cli::args::ColorArg;
use lineao_cli::cli::ViewArgs;

/// What the page opens: a file fetched from `url` (relative to the page), or the options' source.
#[derive(Debug)]
pub struct PageArgs {
    pub url: Option<String>,
    /// `volume=`: a NIfTI volume's address (relative to the page), shown as slices.
    pub volume: Option<String>,
    /// `color=volume:ADDRESS` or `color=tsf:ADDRESS`: a file's address (relative to the page)
    /// whose values colour the lines.
    pub values: Option<ColorArg>,
    /// The viewer's options; its `volume` is `None` and its `color` no file's (a page reads no
    /// file by name).
    pub view: ViewArgs,
    /// `hold=MIB`: the most of a file the page keeps to read it again (for the methods that
    /// work on every point on the CPU); default [`crate::HOLD_BYTES`].
    pub hold_bytes: u64,
}

#[derive(Parser, Debug)]
#[command(name = "lineao-web", no_binary_name = true, disable_help_flag = true, disable_version_flag = true)]
struct PageCli {
    #[command(flatten)]
    view: ViewArgs,
}

/// Keys of `lineao view` that mean nothing in a page.
const NOT_IN_A_PAGE: [&str; 3] = ["screenshot", "frames", "size"];

/// Parses a URL's query string (`search`, with or without its `?`).
pub fn parse(search: &str) -> Result<PageArgs, String> {
    let query = search.strip_prefix('?').unwrap_or(search);
    let (mut url, mut args, mut hold_bytes) = (None, Vec::new(), crate::HOLD_BYTES);
    for (key, value) in form_urlencoded::parse(query.as_bytes()) {
        match &*key {
            "url" if value.is_empty() => return Err("url= needs a file's address".into()),
            "url" => url = Some(value.into_owned()),
            "volume" if value.is_empty() => return Err("volume= needs a NIfTI volume's address".into()),
            "hold" => {
                let mib: u64 = value.parse().map_err(|_| format!("hold= takes MiB, a whole number, got '{value}'"))?;
                hold_bytes = mib << 20;
            }
            key if NOT_IN_A_PAGE.contains(&key) => return Err(format!("'{key}' is not an option of the web page")),
            key if key.starts_with('-') || key.is_empty() => return Err(format!("'{key}' is not an option")),
            key => {
                args.push(format!("--{key}"));
                if !value.is_empty() {
                    args.push(value.into_owned());
                }
            }
        }
    }
    let cli = PageCli::try_parse_from(&args).map_err(|e| {
        let text = e.render().to_string();
        // Its message, up to the usage (a missing option's name is on the lines after the first).
        let message: Vec<&str> = text.lines().take_while(|l| !l.trim().is_empty()).map(str::trim).collect();
        format!("the page's URL: {}", message.join(" ").trim_start_matches("error: "))
    })?;
    let mut view = cli.view;
    // An address, which the page fetches (clap took it as `--volume`, for `slices`' sake).
    let volume = view.volume.take().map(|path| path.to_string_lossy().into_owned());
    let values = view.color.values_file().is_some().then(|| std::mem::replace(&mut view.color, ColorArg::Tangent));
    if url.is_some() && view.scene.is_some() {
        return Err("the page's URL: url= and scene= exclude each other".into());
    }
    let methods = match view.compare {
        Some(pair) => pair.to_vec(),
        None => vec![view.method],
    };
    if methods.iter().any(|m| m.volume.is_some()) {
        return Err(format!("the page's URL: {}", lineao_cli::view::controls::WEB_LEAVES_OUT));
    }
    Ok(PageArgs { url, volume, values, view, hold_bytes })
}

/// The query string of a view: the source and the options a link keeps (methods, preset,
/// camera, and `flags`: the methods' settings and the selection as `lineao view` takes them,
/// an empty value for a switch), in the form [`parse`] reads.
pub fn link(
    (source, volume): (&LinkSource, Option<&str>),
    methods: &[&str],
    preset: lineao::Preset,
    (orbit, ortho): (Option<[f32; 3]>, bool),
    flags: &[(String, String)],
) -> String {
    let mut query = form_urlencoded::Serializer::new(String::new());
    match source {
        LinkSource::Url(url) => query.append_pair("url", url),
        LinkSource::Scene(name) => query.append_pair("scene", name),
        LinkSource::None => &mut query,
    };
    if let Some(volume) = volume {
        query.append_pair("volume", volume);
    }
    match methods {
        [one] => query.append_pair("method", one),
        many => query.append_pair("compare", &many.join(",")),
    };
    query.append_pair("preset", preset.name());
    if let Some([azimuth, elevation, zoom]) = orbit {
        query.append_pair("orbit", &format!("{azimuth:.1},{elevation:.1},{zoom:.3}"));
    }
    if ortho {
        query.append_key_only("ortho");
    }
    for (flag, value) in flags {
        match value.as_str() {
            "" => query.append_key_only(flag),
            value => query.append_pair(flag, value),
        };
    }
    format!("?{}", query.finish())
}

/// Every key the page's URL takes, with what it does: the page's own (`url`, `hold`), then
/// `lineao view`'s options by their names, from the same definitions [`parse`] reads, less
/// those a page cannot use. docs/options.md lists them (generated from this).
pub fn url_keys() -> Vec<(String, String)> {
    let mut keys = vec![
        ("url".to_string(), "a tractogram's address, fetched (relative to the page), with a progress bar".to_string()),
        (
            "hold".to_string(),
            format!("MiB of a file the page keeps to read it again (default {})", crate::HOLD_BYTES >> 20),
        ),
    ];
    let command = <PageCli as clap::CommandFactory>::command();
    for arg in command.get_arguments() {
        let Some(long) = arg.get_long().filter(|long| !NOT_IN_A_PAGE.contains(long)) else { continue };
        let help = arg.get_help().map(|h| h.to_string()).unwrap_or_default();
        let what = match long {
            "volume" => format!("a NIfTI volume's address, fetched and shown as slices (`--volume`: {help})"),
            "color" => format!("as `--color`; `volume:` and `tsf:` take an address, fetched first ({help})"),
            _ => format!("`--{long}`: {help}"),
        };
        keys.push((long.to_string(), what));
    }
    keys
}

/// What a link names as the data.
#[derive(Clone, Debug, PartialEq)]
pub enum LinkSource {
    Url(String),
    Scene(String),
    /// A dropped or picked file, which no link can name.
    None,
}

#[cfg(test)]
mod tests {
    use super::*;
    use lineao::AoMethod;

    #[test]
    fn the_query_is_the_view_commands_options() {
        let page = parse("?url=data%2Fstroke.trk.gz&compare=lineao,ssao&preset=paper&orbit=30,-10,0.5&ortho").unwrap();
        assert_eq!(page.url.as_deref(), Some("data/stroke.trk.gz"));
        let v = &page.view;
        assert_eq!(v.compare.map(|p| p.map(|m| m.screen)), Some([AoMethod::LineAo, AoMethod::Ssao]));
        assert_eq!(v.preset, lineao::Preset::Paper);
        assert_eq!(v.orbit, Some([30.0, -10.0, 0.5]));
        assert!(v.ortho);
        let scene = parse("scene=bundles&method=ssao&debug-view=ao").unwrap();
        assert_eq!(scene.url, None);
        assert_eq!(scene.view.scene.map(|s| s.name()), Some("bundles"));
        assert_eq!(scene.view.method.screen, AoMethod::Ssao);
        assert_eq!(parse("").unwrap().view.method.screen, AoMethod::LineAo, "lineao view's defaults");
        let anatomy = parse("url=stroke.trk.gz&volume=t1.nii.gz&slices=0,-,10").unwrap();
        assert_eq!(anatomy.volume.as_deref(), Some("t1.nii.gz"));
        assert_eq!(anatomy.view.slices, Some([Some(0.0), None, Some(10.0)]));
        assert!(!anatomy.view.opaque_slices);
        assert!(parse("url=stroke.trk.gz&volume=t1.nii.gz&opaque-slices").unwrap().view.opaque_slices);
        // A file whose values colour the lines is an address, fetched by the page.
        let coloured = parse("url=stroke.trk.gz&color=volume:data%2Fz.nii.gz").unwrap();
        assert_eq!(coloured.values, Some(ColorArg::Volume("data/z.nii.gz".into())));
        assert_eq!(coloured.view.color, ColorArg::Tangent, "no file the viewer reads");
        assert_eq!(parse("url=a.tck&color=tsf:a.tsf").unwrap().values, Some(ColorArg::Tsf("a.tsf".into())));
        let field = parse("url=a.trk&color=field:fa").unwrap();
        assert_eq!((field.values, field.view.color), (None, ColorArg::Field("fa".into())));
    }

    #[test]
    fn what_the_command_line_refuses_the_link_refuses_with_its_words() {
        let error = |q: &str| parse(q).unwrap_err();
        assert!(error("method=lineoa").contains("lineoa"), "{}", error("method=lineoa"));
        assert!(error("preset=loud").contains("unknown preset 'loud'"), "{}", error("preset=loud"));
        assert!(error("orbit=1,2").contains("AZIMUTH,ELEVATION,ZOOM"));
        assert!(error("colour=red").contains("--colour"), "{}", error("colour=red"));
        assert!(error("method=sweep").contains("CPU threads"));
        assert!(error("compare=lineao,lineao%2Bsweep").contains("CPU threads"));
        assert!(error("screenshot=a.png").contains("not an option of the web page"));
        assert!(error("url=").contains("needs a file"));
        assert!(error("url=a.trk&scene=bundles").contains("exclude each other"));
        assert!(error("volume=").contains("needs a NIfTI"));
        assert!(error("slices=0,0,0").contains("--volume"), "{}", error("slices=0,0,0"));
    }

    /// A method's described settings are URL keys, as they are flags (the registry's test
    /// method `toy`, which this crate's tests build with): given, applied to the chain; out of
    /// range, refused by the flag's words.
    #[test]
    fn a_methods_settings_are_url_keys() {
        let page = parse("method=toy&toy-radius=1.5&toy-invert").unwrap();
        let mut chain = lineao::ChainSettings::default();
        page.view.methods.apply(&mut chain);
        let given: Vec<&str> = page.view.methods.given.iter().map(|(flag, _)| *flag).collect();
        assert_eq!(given, ["toy-radius", "toy-invert"]);
        let described = AoMethod::from_name("toy").unwrap().info().settings();
        let values: Vec<String> = described.map(|s| s.get(&chain).to_string()).collect();
        assert_eq!(values, ["1.5", "on"]);
        assert!(parse("toy-radius=9").unwrap_err().contains("--toy-radius must be in [0.25, 4] zoom units, got 9"));
    }

    #[test]
    fn a_link_reads_back_as_the_view_it_describes() {
        let query = link(
            (&LinkSource::Url("data/a b.tck".into()), Some("data/t1.nii.gz")),
            &["lineao", "ssao"],
            lineao::Preset::Sparse,
            (Some([12.345, -3.0, 0.75]), true),
            &[],
        );
        let page = parse(&query).unwrap();
        assert_eq!(page.url.as_deref(), Some("data/a b.tck"));
        assert_eq!(page.volume.as_deref(), Some("data/t1.nii.gz"));
        assert_eq!(page.view.volume, None, "an address, not a file the viewer reads");
        assert_eq!(page.view.preset, lineao::Preset::Sparse);
        assert_eq!(page.view.orbit, Some([12.3, -3.0, 0.75]));
        assert!(page.view.ortho);
        let one = parse(&link(
            (&LinkSource::Scene("spiral".into()), None),
            &["ssao"],
            lineao::Preset::Legible,
            (None, false),
            &[],
        ));
        assert_eq!(one.unwrap().view.method.screen, AoMethod::Ssao);
    }

    #[test]
    fn a_link_keeps_the_methods_settings_and_the_selection() {
        use lineao::method::setting::Value;
        use lineao_cli::view::controls::{ColorMode, Controls, RAY_TRACED, RegionRule, methods};
        use lineao_tracts::Region;
        let ssao = methods().into_iter().find(|m| m.screen == AoMethod::Ssao && m.volume.is_none()).unwrap();
        let mut controls = Controls::new([ssao, RAY_TRACED], true, lineao::Preset::Legible);
        // As the panel moves them: the radius sets the range check too, which then moves back.
        for (flag, value) in [("ssao-samples", Value::Count(8)), ("ssao-radius", Value::Number(3.3))] {
            let mut described = AoMethod::Ssao.info().settings();
            described.find(|s| s.flag == flag).unwrap().set(&mut controls.params.chain, value);
        }
        controls.params.chain.ssao.range_world = 8.0;
        // A switch its flag cannot give (the denoiser off where the viewer turns it on) is left out.
        controls.params.chain.raytraced.denoise = None;
        (controls.subset, controls.length) = (0.3, Some([20.0, 80.5]));
        (controls.color, controls.colormap) = (ColorMode::Field("fa".into()), lineao::Colormap::CoolWarm);
        controls.params.chain.slab = Some(lineao::Slab { axis: lineao::SlabAxis::Y, center: -12.5, thickness: 8.0 });
        let transparency = lineao::TransparencySettings { alpha: 0.35, context_alpha: 0.05, layers: 6 };
        controls.params.chain.transparency = Some(transparency);
        controls.regions = vec![
            RegionRule { include: true, region: Region::Sphere { center: [1.5, -2.0, 0.1], radius: 7.25 } },
            RegionRule { include: false, region: Region::Box { min: [-1.0, -2.0, -3.0], max: [4.0, 5.0, 6.5] } },
        ];
        let flags = controls.link_flags();
        let keys: Vec<&str> = flags.iter().map(|(flag, _)| flag.as_str()).collect();
        let kept = [
            "ssao-samples",
            "ssao-radius",
            "ssao-range",
            "colormap",
            "color",
            "slab",
            "alpha",
            "context-alpha",
            "layers",
            "subset",
            "length",
        ];
        assert_eq!(keys, [&kept[..], &["include", "exclude"]].concat());
        let query = link(
            (&LinkSource::Scene("bundles".into()), None),
            &["ssao", "raytraced"],
            lineao::Preset::Legible,
            (None, false),
            &flags,
        );
        let page = parse(&query).unwrap();
        let opened = lineao_cli::view::options(&page.view).controls;
        assert_eq!(opened.selection(), controls.selection());
        assert_eq!((&opened.color, opened.colormap), (&controls.color, controls.colormap));
        assert_eq!(opened.params.chain.slab, controls.params.chain.slab);
        assert_eq!(opened.params.chain.transparency, controls.params.chain.transparency);
        assert_eq!(opened.params.chain.ssao, controls.params.chain.ssao);
        assert_eq!(opened.link_flags(), flags, "the link of the page it opens is the same");
    }
}
