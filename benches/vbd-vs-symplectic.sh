#!/bin/bash
# Whole runs of the cloth scenes, symplectic against block descent at a 60 Hz frame, timed
# from the shell; run from the repository root after `cargo build --release -p hooke-cli`.
H=${HOOKE:-target/release/hooke}
SQ=assets/meshes/square-table.obj

run() { local label="$1"; shift; local s=$(date +%s.%N); $H run "$@" --every 100000 >/dev/null 2>&1; local rc=$?; local e=$(date +%s.%N); echo "$label rc=$rc wall=$(echo "$e - $s" | bc)"; }
for rep in 1 2; do
run "cloth-table symplectic" cloth-table
run "cloth-table vbd" cloth-table --integrator vbd --dt 0.016666666666666666
run "cylinder symplectic" cloth-table --table cylinder
run "cylinder vbd" cloth-table --table cylinder --integrator vbd --dt 0.016666666666666666
run "square symplectic" cloth-table --table $SQ
run "square vbd" cloth-table --table $SQ --integrator vbd --dt 0.016666666666666666
run "cloth-pile symplectic" cloth-pile
run "cloth-pile vbd" cloth-pile --integrator vbd --dt 0.016666666666666666
done
run "cloth-stack vbd" assets/examples/cloth-stack.toml
