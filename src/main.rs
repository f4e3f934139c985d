use clap::Parser;

fn main() {
    // A closed pipe (`irsig atmos show --csv | head`) ends the program
    // quietly, as for any Unix tool, instead of a panic in println!.
    sigpipe::reset();
    let cli = irsig::cli::Cli::parse();
    match irsig::cli::run(cli) {
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("irsig: error: {e:#}");
            std::process::exit(1);
        }
    }
}
