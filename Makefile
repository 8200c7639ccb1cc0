# fdem — thin wrapper over CMake.  The two commands a new user needs:
#   make demo   install missing Debian packages, build (Release), run the demo on 2 ranks
#   make test   install, build and run the whole test suite (unit + MPI tests) with ctest
BUILD    ?= build
JOBS     ?= $(shell nproc)
NP       ?= 2
DEMO     ?= cases/demo/settle.yaml
DEMO_OUT ?= out/demo

.PHONY: demo test build deps clean bench

deps:
	@bash scripts/install-deps.sh

build:
	@bash scripts/install-deps.sh
	@[ -f $(BUILD)/CMakeCache.txt ] || cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	@rm -rf $(DEMO_OUT)
	bash scripts/mpirun.sh -n $(NP) $(BUILD)/fdem run $(DEMO) --out $(DEMO_OUT)
	@/usr/bin/python3 scripts/plot_history.py $(DEMO_OUT) >/dev/null && echo "plot: $(DEMO_OUT)/history.png" || true
	@/usr/bin/python3 scripts/summary.py $(DEMO_OUT)

test: build
	cd $(BUILD) && ctest --output-on-failure -j 1

bench: build
	bash bench/run.sh

clean:
	rm -rf $(BUILD) out
