//! `mrtmap simulate-board`: synthetic checkerboard pairs with exact truth.

use mrtmap_pipeline::calibration::SynthOptions;
use mrtmap_pipeline::calibration::simulate_boards;

use crate::cli::SimulateBoardArgs;

pub fn run(a: &SimulateBoardArgs) -> anyhow::Result<()> {
    let o = SynthOptions {
        pairs: a.pairs,
        partial: a.partial.min(a.pairs),
        seed: a.seed,
        thermal_blur_px: a.blur_px,
        thermal_noise_k: a.noise_k,
        ..SynthOptions::default()
    };
    let n = simulate_boards(&a.out, &o)?;
    outln!(
        "wrote {n} pairs to {} (board {}x{}, {} mm squares; truth.json)",
        a.out.display(),
        o.board.cols,
        o.board.rows,
        o.board.square_m * 1e3
    );
    Ok(())
}
