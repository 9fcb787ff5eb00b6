use std::process::ExitCode;

use clap::Parser;
use voxcone::cli::{Cli, Command};
use voxcone::frontend;

fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Some(Command::Render(args)) => {
            let path = frontend::render::run(&args)?;
            println!("wrote {}", path.display());
        }
        Some(Command::View(args)) => frontend::view::run(args)?,
        Some(Command::Bench(args)) => {
            frontend::bench::run(&args)?;
        }
        Some(Command::Bake(args)) => {
            frontend::bake::run(&args)?;
        }
        Some(Command::Compare(args)) => {
            let options = voxcone::compare::CompareOptions {
                exposure: args.exposure,
                flip_map: args.map.clone(),
                blocks: args.blocks,
            };
            let metrics = voxcone::compare::compare(&args.reference, &args.test, &options)?;
            if let Some(blocks) = &metrics.blocks {
                eprintln!(
                    "LDR-FLIP{} per block ({n}x{n}, rows top to bottom):\n{}",
                    if blocks.brightness_ratio.is_some() {
                        " / test brightness over reference"
                    } else {
                        ""
                    },
                    blocks.table(),
                    n = blocks.blocks
                );
            }
            let text = serde_json::to_string_pretty(&metrics)?;
            println!("{text}");
            if let Some(path) = &args.json {
                std::fs::write(path, &text)
                    .map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))?;
            }
        }
        None if has_display() => {
            // `cargo run` with no arguments: look at the default scene.
            run(Cli::try_parse_from(["voxcone", "view"])?)?;
        }
        None => {
            log::info!("no display found (DISPLAY/WAYLAND_DISPLAY unset): rendering headless");
            run(Cli::try_parse_from(["voxcone", "render"])?)?;
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("info"))
        .format_timestamp(None)
        .init();
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
