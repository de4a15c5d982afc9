//! One module per subcommand, each with `Args` (clap derive) and `run(Args) -> anyhow::Result<()>`.

pub mod bake;
pub mod bench;
pub mod inspect;
pub mod render;
