# The README's two commands. Each installs what it needs first (tools/setup.sh).
.PHONY: run test setup

setup:
	@./tools/setup.sh

# Runs the default scene (2D dam break of Martin & Moyce) into out/dam_break_2d.
run: setup
	cargo run --release -- run scenes/dam_break_2d.toml --overwrite

# The whole test suite, in release mode (the physics tests run real simulations).
test: setup
	cargo test --release
