//! docs/options.md, generated from the options' own declarations: the command line's clap
//! definitions (`render`, `view` and every other subcommand), Python's keywords (read from
//! `render`'s definition, [`crate::kwargs`]), the viewer's keys ([`crate::view::keys`]) and the
//! page's URL keys (given by `lineao-web`, whose parser owns them). A test in `lineao-web`
//! regenerates the page and fails where the file differs, so the docs cannot drift.

use std::fmt::Write;

use clap::CommandFactory;

/// The page's URL keys as `lineao-web` declares them: (key, what it does).
pub type UrlKeys = [(String, String)];

/// The whole of docs/options.md.
pub fn markdown(url_keys: &UrlKeys) -> String {
    let cli = crate::cli::Cli::command();
    let mut out = String::from(
        "# Options\n\n\
         Every option of every front end, generated from its declaration (`lineao_cli::options_doc`;\n\
         the test `the_options_page_is_generated_from_the_declarations` in `crates/lineao-web`\n\
         fails where this page differs, `LINEAO_BLESS=1` rewrites it). The names are stable\n\
         ([reference.md](reference.md)).\n\n\
         **Contents:** [`lineao render`](#lineao-render) · [`lineao view`](#lineao-view) ·\n\
         [the viewer's keys](#the-viewers-keys) · [Python's keywords](#pythons-keywords) ·\n\
         [the page's URL keys](#the-pages-url-keys) · [the other commands](#the-other-commands)\n",
    );
    let render = cli.find_subcommand("render").expect("render is a subcommand");
    let view = cli.find_subcommand("view").expect("view is a subcommand");
    options_table(&mut out, "`lineao render`", render, None);
    options_table(&mut out, "`lineao view`", view, None);
    keys_table(&mut out);
    keywords_table(&mut out);
    url_table(&mut out, url_keys);
    out.push_str("\n## The other commands\n\nTheir options beyond those `lineao render` takes (the source, the method, the settings).\n");
    for name in ["info", "convert", "bench", "score", "bench-load"] {
        let command = cli.find_subcommand(name).expect("a subcommand");
        options_table(&mut out, &format!("`lineao {name}`"), command, Some(render));
    }
    out
}

/// A table of `command`'s options (those `beyond` lacks, where given), one row each.
fn options_table(out: &mut String, title: &str, command: &clap::Command, beyond: Option<&clap::Command>) {
    let level = if beyond.is_some() { "###" } else { "##" };
    let about = command.get_about().map(|a| a.to_string()).unwrap_or_default();
    let _ = write!(out, "\n{level} {title}\n\n{}\n\n| option | default | what |\n|---|---|---|\n", one_line(&about));
    let known = |id: &str| beyond.is_some_and(|b| b.get_arguments().any(|a| a.get_id() == id));
    for arg in command.get_arguments().filter(|a| a.get_id() != "help" && a.get_id() != "version") {
        if known(arg.get_id().as_str()) || arg.get_long().is_some_and(for_tests) {
            continue;
        }
        let name = match arg.get_long() {
            Some(long) => format!("`--{long}{}`", value_names(arg)),
            None => format!("`{}`", arg.get_value_names().and_then(|v| v.first()).map_or(arg.get_id().as_str(), |v| v)),
        };
        let default: Vec<String> = arg.get_default_values().iter().map(|d| d.to_string_lossy().into_owned()).collect();
        let default = if default.is_empty() { String::new() } else { format!("`{}`", default.join(",")) };
        let help = arg.get_long_help().or(arg.get_help()).map(|h| h.to_string()).unwrap_or_default();
        let _ = writeln!(out, "| {name} | {default} | {} |", cell(&help));
    }
}

/// ` <VALUE>` for an option that takes one, nothing for a switch.
fn value_names(arg: &clap::Arg) -> String {
    if !arg.get_action().takes_values() {
        return String::new();
    }
    match arg.get_value_names() {
        Some(names) => names.iter().map(|n| format!(" {n}")).collect(),
        None => format!(" {}", arg.get_id().as_str().to_uppercase()),
    }
}

fn keys_table(out: &mut String) {
    use crate::view::keys::{KEYS, MOUSE, written};
    out.push_str(
        "\n## The viewer's keys\n\nOver the image of `lineao view` and the page, when no text field has the keyboard.\n\n\
         | key | what |\n|---|---|\n",
    );
    for binding in KEYS {
        let _ = writeln!(out, "| {} | {} |", written(binding), cell(binding.help));
    }
    out.push_str("\n| mouse | what |\n|---|---|\n");
    for (gesture, what) in MOUSE {
        let _ = writeln!(out, "| {gesture} | {what} |");
    }
}

fn keywords_table(out: &mut String) {
    out.push_str(
        "\n## Python's keywords\n\n`lineao.render(t, **keywords)` and `lineao.Renderer(t, **keywords)` take `lineao \
         render`'s options with `_` for `-`, checked by the same parsers (`lineao.settings()` lists them \
         with their help).\n\n| keyword | option | default |\n|---|---|---|\n",
    );
    for keyword in crate::args::RenderArgs::keywords().into_iter().filter(|k| !for_tests(&k.name.replace('_', "-"))) {
        let default = keyword.default.map(|d| format!("`{d}`")).unwrap_or_default();
        let _ = writeln!(out, "| `{}` | `--{}` | {default} |", keyword.name, keyword.name.replace('_', "-"));
    }
}

fn url_table(out: &mut String, url_keys: &UrlKeys) {
    out.push_str(
        "\n## The page's URL keys\n\n`?key=value&flag`: `lineao view`'s options by their names, parsed by the same \
         definitions, and the page's own.\n\n| key | what |\n|---|---|\n",
    );
    for (key, what) in url_keys.iter().filter(|(key, _)| !for_tests(key)) {
        let _ = writeln!(out, "| `{key}` | {} |", cell(what));
    }
}

/// Whether `flag` is a setting of a method built for tests only, which users' builds lack.
pub fn for_tests(flag: &str) -> bool {
    lineao::AoMethod::FOR_TESTS.iter().any(|m| m.info().settings().any(|s| s.flag == flag))
}

/// Text on one line.
fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Text for a table's cell: on one line, its bars escaped.
fn cell(text: &str) -> String {
    one_line(text).replace('|', "\\|")
}
