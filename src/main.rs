use clap::Parser;

fn main() {
    let cli = irsig::cli::Cli::parse();
    match irsig::cli::run(cli) {
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("irsig: error: {e:#}");
            std::process::exit(1);
        }
    }
}
