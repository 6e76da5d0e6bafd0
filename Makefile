# Front door of the project. `make run` and `make test` install what is
# missing and build first, so on a fresh Debian machine they are all the
# set-up there is.

BUILD    ?= build
JOBS     ?= $(shell nproc)
SCENARIO ?= sim/scenarios/bench3.yaml
RTF      ?= 1.0
PYTHON   := /usr/bin/python3

# Every Debian package the project uses (build, run, test, bench, lcm-spy, plots).
DEBIAN_PACKAGES := cmake make g++ git liblcm-dev liblcm-bin liblcm-java libjchart2d-java \
  default-jdk-headless libeigen3-dev libnlopt-cxx-dev libnlopt-dev liboctomap-dev \
  libdynamicedt3d-dev libspdlog-dev libcli11-dev libyaml-cpp-dev libgtest-dev \
  libbenchmark-dev libompl-dev libboost-serialization-dev libboost-filesystem-dev \
  libboost-system-dev python3 python3-matplotlib python3-numpy python3-yaml iproute2 \
  util-linux procps

.PHONY: all deps build run test bench spy clean format

all: build

deps:
	@missing=""; for p in $(DEBIAN_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -z "$$missing" ]; then echo "deps: all Debian packages present"; exit 0; fi; \
	echo "deps: installing$$missing"; \
	sudo=""; [ "$$(id -u)" = 0 ] || sudo=sudo; \
	$$sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$sudo apt-get install -y -qq $$missing

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo

build: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

# The main job: the benchmark course flown by all services as separate processes.
# HOSTS=3: on the gcs/onboard1/onboard2 split, three network namespaces on a bridge.
run: deps build
	$(if $(filter-out 1 3,$(HOSTS)),$(error HOSTS=$(HOSTS): use HOSTS=3 for three hosts or leave it unset for one))deploy/$(if $(filter 3,$(HOSTS)),fly_three_hosts.sh,fly.sh) --scenario $(SCENARIO) --rtf $(RTF)

test: deps build
	cd $(BUILD) && ctest --output-on-failure -j 2 --timeout 600

bench: deps build
	cmake --build $(BUILD) -j $(JOBS) --target ofn_benchmarks ofn_tracking_sweep
	bench/run_benchmarks.sh $(BUILD)

spy: deps build
	deploy/spy.sh

format:
	find services sim tests bench -name '*.cpp' -o -name '*.hpp' | xargs clang-format -i

clean:
	rm -rf $(BUILD)
