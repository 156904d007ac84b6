//! `beltrami solvers`: the registered solvers and what each accepts.

use clap::Args;
use serde_json::json;

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
            .map(|s| json!({"name": s.name(), "description": s.description(), "accepts": s.accepts()}))
            .collect();
        println!("{}", serde_json::Value::Array(list));
        return Ok(());
    }
    for s in registry.iter() {
        println!("{:<14} {}", s.name(), s.description());
        println!("{:<14} accepts: {}", "", s.accepts());
    }
    Ok(())
}
