//! `tsukami-vision`: the vision component (see the library's documentation).

fn main() {
    std::process::exit(tsukami_vision::cli::main());
}
