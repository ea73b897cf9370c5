//! `lineao`: render tractography and streamlines with LineAO.
//!
//! Exit codes (docs/reference.md): 0 success, 1 bad input or a failed operation (message on stderr),
//! 2 bad command line. A panic is a bug; it is reported and exits 1, never 101.

use std::process::ExitCode;

use clap::Parser;
use lineao_cli::{bench, bench_load, cli, figure, fit, info, score};

fn main() -> ExitCode {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // SAFETY: single-threaded at this point; silences the Vulkan loader's warnings headless.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
    }
    let cli = cli::Cli::parse();
    let result = std::panic::catch_unwind(|| match cli.command {
        cli::Command::Render(args) => figure::run(&args),
        cli::Command::Bench(args) => bench::run(&args),
        cli::Command::Info(args) => info::run(&args),
        cli::Command::Convert(args) => info::convert(&args),
        cli::Command::BenchLoad(args) => bench_load::run(&args),
        #[cfg(feature = "viewer")]
        cli::Command::View(args) => lineao_cli::view::run(&args),
        #[cfg(not(feature = "viewer"))]
        cli::Command::View(_) => {
            Err(anyhow::anyhow!("this lineao was built without the viewer (cargo feature `viewer`)"))
        }
        cli::Command::Score(args) if args.fit => fit::run(&args),
        cli::Command::Score(args) => score::run(&args),
    });
    match result {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(error)) => {
            eprintln!("lineao: error: {error:#}");
            ExitCode::from(1)
        }
        Err(_) => {
            eprintln!("lineao: internal error (a bug in lineao; please report it with the command line)");
            ExitCode::from(1)
        }
    }
}
