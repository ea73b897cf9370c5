//! docs/options.md is generated from the options' declarations: the command line's, Python's
//! keywords, the viewer's keys and the page's URL keys. This test regenerates it and fails
//! where the file differs; `LINEAO_BLESS=1 cargo test -p lineao-web --test options_doc`
//! rewrites it.

use std::path::Path;

#[test]
fn the_options_page_is_generated_from_the_declarations() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/options.md");
    let page = lineao_cli::options_doc::markdown(&lineao_web::query::url_keys());
    if std::env::var_os("LINEAO_BLESS").is_some() {
        std::fs::write(&path, &page).expect("docs/options.md is writable");
    }
    let written = std::fs::read_to_string(&path).unwrap_or_default();
    if written != page {
        let line = written.lines().zip(page.lines()).position(|(a, b)| a != b).unwrap_or(written.lines().count());
        panic!(
            "docs/options.md differs from the declarations from line {} on; run \
             `LINEAO_BLESS=1 cargo test -p lineao-web --test options_doc` and commit it",
            line + 1
        );
    }
    // Every option of `render` is in the page, and so is every key of the viewer.
    let keywords = lineao_cli::args::RenderArgs::keywords();
    for keyword in keywords.iter().filter(|k| !lineao_cli::options_doc::for_tests(&k.name.replace('_', "-"))) {
        assert!(page.contains(&format!("`{}`", keyword.name)), "{} is not listed", keyword.name);
    }
    assert!(page.contains("`M`") && page.contains("`[`"), "the viewer's keys are listed");
}
