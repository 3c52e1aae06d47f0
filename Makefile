# Odin's entry points. Every target that needs the build runs `setup` first (idempotent).
SHELL := /bin/bash
ROOT  := $(CURDIR)
ENV   := set -eo pipefail; source $(ROOT)/setup.bash;

.PHONY: setup bench-setup bench-kautham build demo test test-stress bench experiments lint mutants soak corpus clean

setup:
	@tools/install.sh

build:
	@source .venv/bin/activate && tools/build.sh

# the three-node chain (a sphere onto a box, out/demo/), then the thesis's grasp
# (out/experiments/grasp/) when the Kautham corpus is there (tools/get_kautham.sh)
demo: setup
	@$(ENV) python tools/demo.py

# the whole suite on every core (pytest-xdist: each node test owns its roscore and ROS_HOME),
# the 15 slowest listed at the end. One worker more than cores: node tests spend much of their
# time waiting for nodes and for simulated time (the suite kept 2 cores 1.2 busy with 2
# workers). Tests go out one at a time in their order, the slow ones first (conftest.py): with
# xdist's default chunks the first worker got every slow test and the others ran dry at the end.
WORKERS := $(shell echo $$(( $$(nproc) + 1 )))
PYTEST  := python -m pytest -p no:cacheprovider -n $(WORKERS) --maxschedchunk 1 --durations=15

test: setup
	@$(ENV) $(PYTEST)

# the same suite with a busy loop on each core: finds the tests that wait for a time instead
# of for the event they need
test-stress: setup
	@$(ENV) tools/with_busy_cores.sh $(PYTEST)

# the peer engines (MuJoCo, PyBullet) in their own venv, .venv-bench: benchmarks only
bench-setup:
	@tools/install.sh --bench

bench: setup bench-setup
	@$(ENV) python tools/bench/run.py

# Kautham 5.1.1, Odin's planning peer in `make bench` (bench_geometric and bench_car_kautham skip
# it until it is built): its build.sh, from $ODIN_KAUTHAM_PEER_DIR (default
# ../shared/peers/kautham), builds it once into build/kautham/; apt installs its Debian
# dependencies; about 7 CPU minutes (JOBS=2 sets make's jobs). tools/bench/kautham_peer.py
bench-kautham:
	@python3 tools/bench/kautham_peer.py build

experiments: setup
	@$(ENV) python tools/experiments/run.py

# catkin_lint over the packages' manifests and CMake files, then ruff over the Python
# (ruff.toml: pyflakes and 100-column lines); both always run, either failing fails the target
lint: setup
	@$(ENV) failed=0; catkin_lint --strict -W2 Odin || failed=1; \
	  ruff check || failed=1; exit $$failed

# mutation testing of the Core (C step code and Python), not part of `make test`: writes
# out/mutants/report.json and report.md, prints the survivors, exits 0 (docs/MUTANTS.md)
mutants: setup
	@$(ENV) python tools/mutants/run.py

# ten minutes of four clients' mixed calls against a simulating world, the Viewer rendering and
# a recorder subscribed; not part of `make test`; figures in out/soak/results.json
soak: setup
	@$(ENV) python tools/soak/run.py

# every problem file of Kautham's whole public corpus (tools/get_kautham.sh --all) through
# problem_info, then built into a world with the Viewer and simulated 2 s, and each geometric
# problem's query planned in its own time limit; not part of `make test`; writes
# out/corpus/report.md and .json and the README's corpus figures
corpus: setup
	@$(ENV) python tools/corpus/run.py

clean:
	rm -rf build out .pytest_cache
