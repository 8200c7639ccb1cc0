# fdem — thin wrapper over CMake. Every target, what it does and its measured time, with where each
# time was measured: README.md#make-targets. Times: wall clock on the 2-core development/CI machine.
#   make fdem           install missing Debian packages, build build/fdem alone (no tests; not measured)
#   make quickstart     make fdem, then docs/quickstart.md's two cases on 2 ranks and their pictures
#                       (the two runs ~2 s and ~6 s)
#   make demo           install missing Debian packages, build (Release), run the geogrid pullout test
#                       (cases/geogrid_pullout/ci.yaml) on 2 ranks at 49 and 93 kPa, make its figures
#                       (4 min 21 s with the build up to date; 9-10 min from a fresh clone)
#   make demo-settle    a settling bed, particles only (~5 s)
#   make test           install, build and run the whole test suite (unit + MPI tests) with ctest
#                       (~27 min on 2 idle cores)
#   make test-sanitize  the unit and MPI tests built with AddressSanitizer + UBSan (build-sanitize/;
#                       ~20 min on CI's 2 cores: make test and make test-sanitize 2 826 s together)
#   make validate       the thesis cases' validation slices on 2 ranks (never in make test): ~7 h
#                       in all: pullout ~1 h 46 min, footing ~1 h 36 min, direct shear ~30 min,
#                       shaft 28 min, void ~2.5 h
#   make build, deps, parity, bench, bench-order, bench-scaling, clean: README.md#make-targets
BUILD    ?= build
JOBS     ?= $(shell nproc)
NP       ?= 2
DEMO     ?= cases/geogrid_pullout/ci.yaml
DEMO_OUT ?= out/pullout_ci

SAN_BUILD ?= build-sanitize
# Unit tests: ASan + UBSan + LeakSanitizer. Open MPI, PMIx and hwloc keep allocations until exit
# that LeakSanitizer reports as leaks of their own (a unit test that starts fdem): suppressed by
# library (tests/support/lsan.supp); for the suppressions to match, their components stay loaded
# (no dlclose) and malloc stacks are unwound fully (the MPI libraries have no frame pointers).
SAN_ENV  = ASAN_OPTIONS=detect_leaks=1:fast_unwind_on_malloc=0:check_initialization_order=1 \
           LSAN_OPTIONS=suppressions=$(CURDIR)/tests/support/lsan.supp:print_suppressions=0 \
           UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
           OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1
# MPI tests: ASan + UBSan, no leak checking (Open MPI's own leaks; full unwinding costs time).
SAN_ENV_MPI = ASAN_OPTIONS=detect_leaks=0:check_initialization_order=1 \
           UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Left out of the sanitizer run to keep it near 20 min on 2 cores (covered by `make test`; the
# 1-rank run of the same tests stays): docs/verification.md.
SAN_EXCLUDE ?= ^(mpi_coupling_np[23]|mpi_fem_solver_np3)$$

.PHONY: fdem quickstart demo demo-settle test update-references test-sanitize build deps clean bench bench-order bench-scaling validate validate-pullout validate-footing validate-direct-shear validate-shaft validate-void parity

deps:
	@bash scripts/install-deps.sh

build:
	@bash scripts/install-deps.sh
	@[ -f $(BUILD)/CMakeCache.txt ] || cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

# the fdem binary alone (no tests): what docs/quickstart.md builds
fdem:
	@bash scripts/install-deps.sh
	@[ -f $(BUILD)/CMakeCache.txt ] || cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS) --target fdem

# docs/quickstart.md's two cases and their pictures (out/settle_box/run.png, out/plate_box/run.png)
quickstart: fdem
	@rm -rf out/settle_box out/plate_box
	bash scripts/mpirun.sh -n $(NP) $(BUILD)/fdem run cases/quickstart/settle_box.yaml
	/usr/bin/python3 scripts/plot_run.py out/settle_box
	bash scripts/mpirun.sh -n $(NP) $(BUILD)/fdem run cases/quickstart/plate_box.yaml
	/usr/bin/python3 scripts/plot_run.py out/plate_box

demo: build
	@rm -rf $(DEMO_OUT)_49 $(DEMO_OUT)_93 $(DEMO_OUT)_figures
	bash scripts/mpirun.sh -n $(NP) $(BUILD)/fdem run $(DEMO) --out $(DEMO_OUT)_49
	bash scripts/mpirun.sh -n $(NP) $(BUILD)/fdem run $(DEMO) --specimen $(DEMO_OUT)_49/specimen.h5 \
	  --set 'walls[top].motion.servo.stress=93000' --out $(DEMO_OUT)_93
	/usr/bin/python3 scripts/pullout_report.py $(DEMO_OUT)_49 $(DEMO_OUT)_93 --figures $(DEMO_OUT)_figures
	@echo "fdem demo: figures in $(DEMO_OUT)_figures/ (pullout force, grid displacement, rib force, friction/bearing split,"
	@echo "  bearing per rib, soil stress and displacement); ParaView: $(DEMO_OUT)_49/fe.xdmf, particles.xdmf, force_network.xdmf"

# The first demo (a settling bed, 5 s): particles only.
demo-settle: build
	@rm -rf out/demo
	bash scripts/mpirun.sh -n $(NP) $(BUILD)/fdem run cases/demo/settle.yaml --out out/demo
	@/usr/bin/python3 scripts/plot_history.py out/demo >/dev/null && echo "plot: out/demo/history.png" || true
	@/usr/bin/python3 scripts/summary.py out/demo

test: build
	cd $(BUILD) && ctest --output-on-failure -j 1

# rewrite the CI cases' reference results from this build (tests/reference/; docs/verification.md#reference-results):
# for a change that moves the physics on purpose -- the diff of tests/reference/ is what review reads
REFERENCE_TESTS = cli_lab_direct_shear|cli_run_lab|cli_pack_k0|cli_strip_footing|cli_pullout|cli_void|cli_shaft|cli_pipe|cli_appendix
update-references: build
	cd $(BUILD) && FDEM_REFERENCE_UPDATE=1 ctest --output-on-failure -j 1 -R '^($(REFERENCE_TESTS))$$'

test-sanitize:
	@bash scripts/install-deps.sh
	@[ -f $(SAN_BUILD)/CMakeCache.txt ] || cmake -S . -B $(SAN_BUILD) -DCMAKE_BUILD_TYPE=Release -DFDEM_SANITIZE=ON
	cmake --build $(SAN_BUILD) -j $(JOBS)
	cd $(SAN_BUILD) && $(SAN_ENV) ctest --output-on-failure -j 1 -L '^unit$$' -E '$(SAN_EXCLUDE)'
	cd $(SAN_BUILD) && $(SAN_ENV_MPI) ctest --output-on-failure -j 1 -L '^mpi$$' -E '$(SAN_EXCLUDE)'

# Validation slices (docs/cases/): the thesis's grains, the domain cut only where the
# thesis finds no response. Each writes out/<case>_slice_*/ and its report.
VAL_OUT ?= out/pullout_slice
validate: validate-pullout validate-footing validate-direct-shear validate-shaft validate-void

validate-pullout: build
	@rm -rf $(VAL_OUT)_49 $(VAL_OUT)_93 $(VAL_OUT)_figures
	bash scripts/mpirun.sh -n $(NP) $(BUILD)/fdem run cases/geogrid_pullout/slice.yaml --out $(VAL_OUT)_49
	bash scripts/mpirun.sh -n $(NP) $(BUILD)/fdem run cases/geogrid_pullout/slice.yaml \
	  --specimen $(VAL_OUT)_49/specimen.h5 --set 'walls[top].motion.servo.stress=93000' --out $(VAL_OUT)_93
	/usr/bin/python3 scripts/pullout_report.py $(VAL_OUT)_49 $(VAL_OUT)_93 \
	  --figures $(VAL_OUT)_figures

# the strip footing, N = 0, 1, 2 (a finished run is kept: delete out/footing_slice_n* to redo),
# after the triaxial and plane-strain tests of its sand (the friction angles of the classical
# bearing capacity): phi ~15 min, then on 2 ranks N = 0 14 min, N = 1 32 min, N = 2 35 min, packing
# included (docs/performance.md#time-to-solution-with-the-holds-of-issue-57-2026-12-07)
validate-footing: build
	RANKS=$(NP) FDEM=$(BUILD)/fdem bash scripts/strip_footing.sh phi out/footing_phi
	RANKS=$(NP) FDEM=$(BUILD)/fdem TRIAXIAL="$(foreach s,5 10 25 50,out/footing_phi_$(s) out/footing_phi_ps_$(s))" \
	  bash scripts/strip_footing.sh slice out/footing_slice

# the thesis's direct-shear calibration (ch. 3.5): the full-size box packed the thesis's way, two
# packing seeds x 13.6 / 27.3 / 40.9 kPa, the report (docs/cases/direct_shear.md; the six runs ~30 min)
validate-direct-shear: build
	RANKS=$(NP) FDEM=$(BUILD)/fdem bash scripts/direct_shear.sh out/direct_shear

# the shaft's active earth pressure (ch. 3): the validation slice (a quarter model, L 0.40 m, H 1 m,
# ~100 000 grains rained in 10 layers, the radius reduced in 7 held steps to 5 mm) and the report
# (docs/cases/shaft.md; K0 of the packing: cases/specimens/k0_column.yaml)
validate-shaft: build
	@rm -rf out/shaft_slice out/shaft_slice_figures
	bash scripts/mpirun.sh -n $(NP) $(BUILD)/fdem run cases/shaft/slice.yaml --out out/shaft_slice
	/usr/bin/python3 scripts/shaft_report.py out/shaft_slice --figures out/shaft_slice_figures

# the fill over a void (ch. 6): unreinforced, reinforced, reinforced with a frictionless interface
# (the validation slice: the thesis's 1.1 m length and grains, 0.118 m wide; ~100 000 grains) and
# the report (docs/cases/void.md; a finished run is kept: delete out/void_slice_* to redo)
validate-void: build
	RANKS=$(NP) FDEM=$(BUILD)/fdem bash scripts/void.sh slice out/void_slice

# fdem's contact kernel against YADE 2023.02a step by step (installs Debian's yade if missing): the
# protocols of tests/parity/ run in YADE, replayed through normal_law + contact_force, the parity
# table printed (docs/verification.md#parity-against-yade; the stored histories run in make test)
parity: build
	BUILD=$(BUILD) bash scripts/parity.sh

bench: build
	bash bench/run.sh
	bash bench/flow_peers.sh

# does the speed depend on the input's grain numbering? a 1 M-grain bed (ten tiles of the dense
# bed: needs make bench first), its ids as tiled and shuffled, 1 rank (docs/performance.md#order-keys)
bench-order: build
	bash bench/id_order.sh

# ghosts and traffic per rank on 1-8 ranks, the 10 M-grain extrapolation, strong and weak scaling
# on this machine's cores (bench/results/scaling.*; docs/performance.md#scaling-out)
bench-scaling: build
	bash bench/scaling.sh

clean:
	rm -rf $(BUILD) $(SAN_BUILD) out
