//! Prints a drape specimen of irregular triangles as OBJ, for `hooke drape --mesh`:
//! `cargo run -p hooke-scene --example drape_disc -- DIAMETER_M RING_SPACING_M > disc.obj`
//! (default 0.30 m across, rings 0.005 m apart: four times the built-in disc's vertices).

fn main() {
    let mut args = std::env::args().skip(1);
    let mut number = |default: f64, what: &str| -> f64 {
        match args.next() {
            None => default,
            Some(text) => match text.parse::<f64>() {
                Ok(x) if x.is_finite() && x > 0.0 => x,
                _ => {
                    eprintln!("drape_disc: {what}: expected metres above 0, found \"{text}\"");
                    std::process::exit(2);
                }
            },
        }
    };
    let diameter = number(0.30, "DIAMETER_M");
    let spacing = number(0.005, "RING_SPACING_M");
    print!(
        "{}",
        hooke_scene::example_meshes::drape_disc_obj(diameter, spacing)
    );
}
