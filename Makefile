# Front door of the project. `make run` and `make test` install what is
# missing and build first, so on a fresh Debian machine they are all the
# set-up there is.

BUILD    ?= build
JOBS     ?= $(shell nproc)
SCENARIO ?= sim/scenarios/bench3.yaml
RTF      ?= 1.0
PORT     ?= 8765
SPEED    ?= 1.0
PYTHON   := /usr/bin/python3

# Every Debian package the project uses (build, run, test, bench, lcm-spy, plots).
DEBIAN_PACKAGES := cmake make g++ git liblcm-dev liblcm-bin liblcm-java libjchart2d-java \
  default-jdk-headless libeigen3-dev libnlopt-cxx-dev libnlopt-dev liboctomap-dev \
  libdynamicedt3d-dev libspdlog-dev libcli11-dev libyaml-cpp-dev libgtest-dev \
  libbenchmark-dev libompl-dev libboost-serialization-dev libboost-filesystem-dev \
  libboost-system-dev python3 python3-matplotlib python3-numpy python3-yaml iproute2 \
  util-linux procps libcpp-httplib-dev nlohmann-json3-dev pkg-config \
  libsodium-dev
# Only `make test` needs these: the headless browser that loads the live
# viewer's page, and Pillow to read its screenshot. `make run` pulls no browser.
TEST_PACKAGES := chromium python3-pil nftables

.PHONY: all deps test-deps build flight run replay test bench faults fuzz spy clean format

all: build

# install_missing PACKAGES: apt-get installs those not installed yet.
define install_missing
	@missing=""; for p in $(1); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -z "$$missing" ]; then echo "deps: all Debian packages present"; exit 0; fi; \
	echo "deps: installing$$missing"; \
	sudo=""; [ "$$(id -u)" = 0 ] || sudo=sudo; \
	$$sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$sudo apt-get install -y -qq $$missing
endef

deps:
	$(call install_missing,$(DEBIAN_PACKAGES))

test-deps:
	$(call install_missing,$(DEBIAN_PACKAGES) $(TEST_PACKAGES))

# Optimised as flown, with line tables only (-g1): a backtrace names every
# function, file and line, and the build is a third shorter than with full
# debug information (docs/TESTING.md). For gdb's local variables, configure
# a folder of your own with -DCMAKE_BUILD_TYPE=RelWithDebInfo or Debug.
$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG"

build: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

# What a flight, its report and a replay run: the services, the flight
# monitor and report, the live viewer and its page. `make run` and `make
# replay` build only these (the tests and benchmarks are most of a full
# build); `make test` builds everything.
FLIGHT_TARGETS := ofn_vehicle_sim ofn_controller ofn_mission_uplink ofn_flight_monitor \
  ofn_obstacle_injector ofn_sensor_interface ofn_mapper ofn_global_planner ofn_rh_optimizer \
  ofn_flight_report ofn_viewer ofn_viewer_web ofn_bus_keygen ofn_heartbeat_probe

flight: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS) --target $(FLIGHT_TARGETS)

# The main job: the benchmark course flown by all services as separate processes.
# HOSTS=3: on the gcs/onboard1/onboard2 split, three network namespaces on a bridge.
# WATCH=1: the flight live in a browser (deploy/watch.sh); the URL is printed.
run: deps flight
	$(if $(filter-out 1 3,$(HOSTS)),$(error HOSTS=$(HOSTS): use HOSTS=3 for three hosts or leave it unset for one))$(if $(and $(filter 1,$(WATCH)),$(filter 3,$(HOSTS))),$(error WATCH=1 watches the one-host flight: leave HOSTS unset))deploy/$(if $(filter 3,$(HOSTS)),fly_three_hosts.sh,fly.sh) --scenario $(SCENARIO) --rtf $(RTF)$(if $(filter 1,$(WATCH)), --watch --port $(PORT))

# A recorded flight (LOG=path/to/flight.lcm, or LOG=latest) played into the
# live viewer on a private bus; the page stays up after the log ends (Ctrl-C).
# RERUN=<scenario of that flight>: the mapper and planners run again on it.
replay: deps flight
	$(if $(LOG),,$(error LOG=path/to/flight.lcm or LOG=latest: the flight log to replay))deploy/watch.sh --keep --port $(PORT) --log /tmp/ofn_viewer-replay.log -- deploy/replay.sh $(LOG) --speed $(SPEED)$(if $(RERUN), --rerun $(RERUN))

# ctest in two lanes: the integration tests as usual, the unit tests beside
# them at nice 19 in the CPU the flights leave idle (tests/run_tests.sh).
test: test-deps build
	tests/run_tests.sh $(BUILD)

bench: deps build
	cmake --build $(BUILD) -j $(JOBS) --target ofn_benchmarks ofn_tracking_sweep
	bench/run_benchmarks.sh $(BUILD)

# The fault suite (docs/TESTING.md#the-fault-suite): bench3 on the three-host
# split under each fault in turn (loss, a blackout, kill -9 and SIGSTOP of
# every service, CPU starvation, delay, jitter, duplication and reordering
# between the hosts), judged and tabled. About 40 minutes; root.
# FAULTS=loss-30,kill-rh_optimizer flies only those rows.
FAULTS ?=
faults: test-deps flight
	$(PYTHON) bench/fault_suite.py --bin $(BUILD)/bin --rtf $(RTF)$(if $(FAULTS), --only $(FAULTS))

# The bus fuzz (docs/TESTING.md#the-bus-fuzz): out_and_back flown by every
# service at half real time, once as it is and once while 10^6 malformed
# messages go to every channel; no crash, no restart, rejections counted,
# memory bounded. About 11 minutes, in a private network namespace.
# FUZZ_MESSAGES=100000 sends fewer.
FUZZ_MESSAGES ?= 1000000
fuzz: deps flight
	cmake --build $(BUILD) -j $(JOBS) --target ofn_bus_fuzz
	$(PYTHON) bench/bus_fuzz.py --bin $(BUILD)/bin --messages $(FUZZ_MESSAGES)

spy: deps build
	deploy/spy.sh

format:
	find services sim tests bench -name '*.cpp' -o -name '*.hpp' | xargs clang-format -i

clean:
	rm -rf $(BUILD)
