//! One module per subcommand, each with `Args` (clap derive) and `run(Args) -> anyhow::Result<()>`.

pub mod bake;
pub mod bench;
pub mod bench_silhouettes;
pub mod bench_sweep;
pub mod inspect;
pub mod render;
pub mod view;
