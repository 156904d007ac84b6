//! `beltrami solvers`: the registered solvers, what each accepts and its options.

use clap::Args;

#[derive(Debug, Args)]
pub struct SolversArgs {
    /// Print a JSON array instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &SolversArgs) -> anyhow::Result<()> {
    let registry = beltrami::registry();
    if args.json {
        let list: Vec<_> = registry
            .iter()
            .map(beltrami::catalog::solver_json)
            .collect();
        println!("{}", serde_json::Value::Array(list));
        return Ok(());
    }
    for s in registry.iter() {
        print!("{}", beltrami::catalog::solver_text(s));
    }
    Ok(())
}
