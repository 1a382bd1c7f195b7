//! PMV/PPD over many inputs, one thread: the kernel behind the Python package's `pmv_ppd_iso`
//! (issue 39's 777×444 grid is 345,000 inputs; this bench takes 100,000 random valid ones, the
//! ranges `bench/python_peer.py` draws from), beside the same inputs one at a time. `cargo bench -p mrtmap-physics --bench pmv`.
#![allow(clippy::unwrap_used)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mrtmap_physics::{Iso7730Edition, PmvInputs, Temperature, pmv_ppd_edition, pmv_ppd_many};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn inputs(n: usize) -> Vec<PmvInputs> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    (0..n)
        .map(|_| PmvInputs {
            air: Temperature::from_celsius(rng.random_range(10.0..30.0)),
            mrt: Temperature::from_celsius(rng.random_range(10.0..40.0)),
            relative_air_speed_m_s: rng.random_range(0.0..1.0),
            relative_humidity_pct: rng.random_range(5.0..95.0),
            met: rng.random_range(0.8..4.0),
            clo: rng.random_range(0.0..2.0),
            external_work_met: 0.0,
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let inp = inputs(100_000);
    let mut g = c.benchmark_group("pmv_ppd_many");
    g.throughput(Throughput::Elements(inp.len() as u64));
    g.sample_size(20);
    // The batch beside the same inputs one at a time, alternated, so that the machine's slow and
    // fast moments fall on both alike.
    for round in 0..2 {
        g.bench_function(format!("many/{round}"), |b| {
            b.iter(|| pmv_ppd_many(&inp, Iso7730Edition::Y2025));
        });
        g.bench_function(format!("one_at_a_time/{round}"), |b| {
            b.iter(|| {
                inp.iter()
                    .map(|i| pmv_ppd_edition(i, Iso7730Edition::Y2025))
                    .collect::<Vec<_>>()
            });
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
