//! What 8 (and 16) bits of `n` achieve: the relative `k_a` error of each curve over the range
//! the maps use, for a typical project (the spot texture, a log gradient of `n` from 1 to
//! 4096, 50 strokes) at 1024^2. Prints a markdown table (`cargo run --release --example
//! n_encoding`).

use kapaint::export::encoding::rank_encodings;
use kapaint::reflectance::{AmbientApprox, ShadingModel};

fn main() -> Result<(), String> {
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/testdata/spot/spot_texture.png");
    let doc = kapaint::report::typical::typical_document(
        1024,
        texture.exists().then_some(texture.as_path()),
        50,
    )?;
    let (lo, hi) = kapaint::export::encoding::n_range(doc.maps());
    println!("n in [{lo}, {hi}]\n");
    println!("| model | bits | curve | max rel k_a error | mean rel k_a error |");
    println!("|---|---|---|---|---|");
    for model in [ShadingModel::Phong, ShadingModel::BlinnPhong] {
        for bits in [8, 16] {
            for (e, err) in rank_encodings(doc.maps(), model, AmbientApprox::Fast, bits) {
                println!(
                    "| {} | {bits} | {:?} | {:.3e} | {:.3e} |",
                    model.name(),
                    e.curve,
                    err.max,
                    err.mean
                );
            }
        }
    }
    Ok(())
}
