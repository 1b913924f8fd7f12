//! The `hemi` command line: parses the command and dispatches to its module.

mod commands;
mod engine;
mod input;
mod options;
mod output;
mod pipeline;
mod progress;

use anyhow::Result;
use clap::{Parser, Subcommand};
use commands::{bench, board, form_factors, irradiance, render, solve, trace};
use std::io::Write;

#[derive(Parser)]
#[command(
    name = "hemi",
    version,
    about = "Generalized two-pass radiosity on the hemi co-processor"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Both passes: writes the image (8-bit sRGB PNG, linear EXR or Radiance HDR, by extension).
    Render(render::RenderArgs),
    /// Pass-1 form factors between the scene's patches.
    FormFactors(form_factors::FormFactorsArgs),
    /// Pass 1 and the solve: radiosity per patch (--ply, --gltf: the solution as meshes).
    Solve(solve::SolveArgs),
    /// Irradiance at points read from stdin (`x y z dx dy dz` per line), printed `r g b` as
    /// each line is read.
    Irradiance(irradiance::IrradianceArgs),
    /// Nearest hit of rays read from stdin (`x y z dx dy dz`): `t patch u v` or `miss`, as each
    /// line is read.
    Trace(trace::TraceArgs),
    /// Benchmarks (speed is measured here, never asserted in tests).
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// The ray engine (board) itself.
    #[command(subcommand)]
    Board(board::BoardCommand),
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    // `--backend model` builds a ~100 KB accelerator model per worker thread, on its stack;
    // unoptimised builds copy it several times while building it, beyond rayon's 2 MiB default.
    let _ = rayon::ThreadPoolBuilder::new()
        .stack_size(16 << 20)
        .build_global();
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    match cli.command {
        Command::Render(args) => render::run(args, &mut out)?,
        Command::FormFactors(args) => form_factors::run(args, &mut out)?,
        Command::Solve(args) => solve::run(args, &mut out)?,
        Command::Irradiance(args) => irradiance::run(args, &mut out)?,
        Command::Trace(args) => trace::run(args, &mut out)?,
        Command::Bench(command) => bench::run(command, &mut out)?,
        Command::Board(command) => board::run(command, &mut out)?,
    }
    out.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;

    /// Every command says what it does and every argument what it means in `--help`.
    #[test]
    fn every_command_and_argument_is_described() {
        fn walk(cmd: &clap::Command, path: &str, missing: &mut Vec<String>) {
            if cmd.get_about().is_none() {
                missing.push(format!("{path} (the command)"));
            }
            for a in cmd.get_arguments() {
                if a.get_help().is_none() && !["help", "version"].contains(&a.get_id().as_str()) {
                    missing.push(format!("{path} {}", a.get_id()));
                }
            }
            for s in cmd.get_subcommands().filter(|s| s.get_name() != "help") {
                walk(s, &format!("{path} {}", s.get_name()), missing);
            }
        }
        let mut cmd = Cli::command();
        cmd.build();
        let mut missing = Vec::new();
        walk(&cmd, "hemi", &mut missing);
        assert!(missing.is_empty(), "undescribed: {missing:?}");
    }
}
