//! The integration tests: one binary, each file of tests/ a module of it (`autotests = false`
//! in Cargo.toml). Linked once instead of once per file, and with the shared helpers (common,
//! procs, view_session) compiled once, the suite's release build took 2m10s instead of 3m16s
//! after a change to the library on the 2-core VM (docs/performance.md, "The suite's time"), and
//! the test harness spreads the long tests of every file over both cores.
//!
//! One file's tests: `cargo test --release --test suite line_scenarios::` (or `tools/test
//! line_scenarios::`); one test: `tools/test shipped_scenarios::bench_sweep_as_documented`.

mod common;
mod procs;
mod view_session;

mod audit_compare;
mod bad_scenarios;
mod batch;
mod bench_cli;
mod bench_scenarios;
mod calibrate;
mod calibrate_bruise;
mod compressed_outputs;
mod damage;
mod damped_accuracy;
mod damping_models;
mod determinism;
mod doc_examples;
mod doc_figures;
mod energy;
mod energy_pressure;
mod extremes;
mod fig5_layers;
mod file_formats;
mod fuzz_scenarios;
mod generators;
mod geometry;
mod handling_line;
mod hertz_impact;
mod layout;
mod liggghts_parity;
mod line_audit;
mod line_fates;
mod line_scenarios;
mod line_shapes;
mod mesh_merge;
mod moving_parts;
mod moving_sources;
mod padding;
mod patch_shift;
mod plots;
mod plugin_api;
mod presets;
mod pulse_fit;
mod regression_adaptive_moving_part;
mod regression_free_roller_inertia;
mod regression_moving_bin_entry;
mod regression_pile_chatter;
mod regression_probe_budget;
mod regression_probe_files;
mod regression_roller_bed_count;
mod regression_scene_bounds_plane;
mod regression_spinning_apple_at_rest;
mod regression_tunnelling;
mod restitution_eq12;
mod riders;
mod rigid_surfaces;
mod rollers;
mod rolling_damping_bound;
mod rolling_resistance;
mod run_folder;
mod sampling_independence;
mod shape_contact;
mod shape_input;
mod shards;
mod shipped_scenarios;
mod sleep_rule;
mod sleep_wake;
mod slip_to_roll;
mod slope_rest;
mod stepping;
mod test_command;
mod tradeoff_tables;
mod transitions;
mod twisting;
mod validation;
mod validation_errata;
mod view_answers;
mod view_browser;
mod view_errors;
mod vtk;
