# mmtrack task runner. Every recipe is a plain cargo command, so everything
# here also works without `just` (see README).

set positional-arguments

# List recipes.
default:
    @just --list

# Ingest a raw dataset: just ingest oxford <folder> -o <recording.mcap>
ingest *args:
    cargo run -q -p mmtrack-cli -- ingest "$@"

# Run a pipeline on a recording (odometry, mpc, beam, slam).
process *args:
    cargo run -q -p mmtrack-cli -- process "$@"

# Metrics and plots from Parquet tables.
analyze *args:
    cargo run -q -p mmtrack-cli -- analyze "$@"

# The whole chain on the embedded demo data.
demo *args:
    cargo run -q -p mmtrack-cli -- demo "$@"

# Show what a recording or table directory holds.
inspect *args:
    cargo run -q -p mmtrack-cli -- inspect "$@"

# The mmtrack binary with HDF5 / MATLAB v7.3 input for `ingest cir` (needs libhdf5: apt-get install libhdf5-dev).
build-hdf5:
    cargo build --release -p mmtrack-cli --features hdf5

# Tests of the HDF5 / MATLAB v7.3 reader (needs libhdf5).
test-hdf5:
    cargo test -p mmtrack-ingest --features hdf5 -- --show-output

# All tests (the same command CI runs).
test:
    cargo test --workspace -- --show-output

# Benchmarks in release mode; refresh the results blocks of docs/benchmarks.md.
bench:
    cargo run -q --release -p mmtrack-cli -- bench io --check --readme docs/benchmarks.md
    cargo run -q --release -p mmtrack-cli -- bench ingest --readme docs/benchmarks.md --from ../shared/realdata/oxford-radar-tiny
    cargo run -q --release -p mmtrack-cli -- bench ingest --readme docs/benchmarks.md
    cargo run -q --release -p mmtrack-cli -- bench odometry --readme docs/benchmarks.md
    cargo run -q --release -p mmtrack-cli -- bench mpc --readme docs/benchmarks.md

# Issue #5's convoy evaluation: the paper's 1666 simulated sets, MPC detection
# and tracking, statistics against the simulator's truth (report:
# out/convoy/analysis/report.md). Extra arguments go to the simulation, e.g.
# `just convoy --sets 100`.
convoy *args:
    cargo run -q --release -p mmtrack-cli -- simulate sounder --scenario data/sounder/convoy-tunnel.toml -o out/convoy/convoy.mcap --force "$@"
    cargo run -q --release -p mmtrack-cli -- process mpc out/convoy/convoy.mcap -o out/convoy/tables --force
    cargo run -q --release -p mmtrack-cli -- analyze out/convoy/tables -o out/convoy/analysis --force

# Fuzz the byte-level readers offline, e.g. `just fuzz all --seconds 600` or
# `just fuzz npy --seconds 60`; findings go to target/fuzz-findings/<target>/.
# The fuzz profile is release with overflow checks and debug assertions.
fuzz *args:
    cargo run -q --profile fuzz -p mmtrack-fuzz -- "$@"

# Paper experiments.
reproduce *args:
    cargo run -q --release -p mmtrack-cli -- reproduce "$@"

# Regenerate schemas/ and data/ fixtures from the code.
regenerate:
    cargo run -q -p mmtrack-cli -- schemas --write schemas
    cargo run -q -p mmtrack-cli -- simulate radar --scenario data/demo/fixture-scenario.toml --format oxford -o data/demo/oxford-demo --force
