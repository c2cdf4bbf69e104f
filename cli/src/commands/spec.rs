//! `snapgen spec`: the contract between host and board, written out for users' firmware and
//! tools (`--emit DIR`: a C header, a JSON description, the protocol's tables in Markdown),
//! or the generated blocks of docs/PROTOCOL.md and docs/BOARDS.md brought up to date
//! (`--update-docs`). Everything
//! comes from the `snapgen_spec` crate, with the design facts the model adds
//! (`snapgen_model::spec_facts`).

use std::path::PathBuf;

use anyhow::Context;
use snapgen_spec::emit;

/// Write the contract's files, or update the protocol page.
#[derive(clap::Args)]
#[group(required = true, multiple = true)]
pub struct Args {
    /// Write snapgen_protocol.h, snapgen_protocol.json and snapgen_protocol_tables.md here.
    #[arg(long)]
    emit: Option<PathBuf>,
    /// Rewrite the generated blocks of PROTOCOL.md and BOARDS.md in `--docs` (between their
    /// `<!-- spec:NAME -->` markers) from the contract; the prose is left as it is.
    #[arg(long)]
    update_docs: bool,
    /// The docs directory `--update-docs` works in.
    #[arg(long, default_value = "docs", requires = "update_docs")]
    docs: PathBuf,
}

/// Runs the subcommand.
pub fn run(a: Args) -> anyhow::Result<()> {
    let facts = snapgen_model::spec_facts();
    if let Some(dir) = &a.emit {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        for (name, text) in emit::files(&facts)? {
            let p = dir.join(name);
            std::fs::write(&p, text).with_context(|| format!("cannot write {}", p.display()))?;
            println!("wrote {}", p.display());
        }
    }
    for page in emit::markdown::PAGES.map(|p| a.docs.join(p)) {
        if !a.update_docs {
            break;
        }
        let old = std::fs::read_to_string(&page)
            .with_context(|| format!("cannot read {}", page.display()))?;
        let new = emit::markdown::update(&old, &facts)
            .with_context(|| format!("{}: its generated blocks", page.display()))?;
        if new == old {
            println!("{} is up to date", page.display());
        } else {
            std::fs::write(&page, new)
                .with_context(|| format!("cannot write {}", page.display()))?;
            println!("updated {}", page.display());
        }
    }
    Ok(())
}
