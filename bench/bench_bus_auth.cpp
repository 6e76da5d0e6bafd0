// Cost of the authenticated bus per message: signing on publish and
// checking on receipt (Ed25519, libsodium), for a navigation state (268
// bytes encoded) and a LIDAR scan (about 23 KB), the smallest and largest
// messages a service handles at its own rate.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <map>
#include <vector>

#include "ofn/bus_auth/authenticator.hpp"

namespace {

using ofn::bus_auth::Authenticator;

struct Pair {
  Authenticator sender;
  Authenticator receiver;
};

Pair make_pair(int64_t& now) {
  const auto policy =
      ofn::bus_auth::PublishPolicy::parse("publishers:\n  a: [X]\n  b: [Y]\n", "bench policy");
  std::map<std::string, ofn::bus_auth::KeyPair> pairs{{"a", ofn::bus_auth::generate_key_pair()},
                                                      {"b", ofn::bus_auth::generate_key_pair()}};
  std::map<std::string, ofn::bus_auth::PublicKey> keys;
  for (const auto& [role, pair] : pairs) keys[role] = pair.public_key;
  const auto clock = [&now] { return now; };
  return {Authenticator("a", pairs["a"].secret_key, keys, policy, clock),
          Authenticator("b", pairs["b"].secret_key, keys, policy, clock)};
}

void BM_BusAuthSeal(benchmark::State& state) {
  int64_t now = 1'800'000'000'000'000;
  auto pair = make_pair(now);
  const std::vector<uint8_t> payload(static_cast<size_t>(state.range(0)), 0x5a);
  std::vector<uint8_t> message;
  for (auto _ : state) {
    message = payload;
    pair.sender.seal("X", message);
    benchmark::DoNotOptimize(message.data());
  }
  state.SetBytesProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_BusAuthSeal)->Arg(268)->Arg(23000)->Unit(benchmark::kMicrosecond);

void BM_BusAuthOpen(benchmark::State& state) {
  int64_t now = 1'800'000'000'000'000;
  auto pair = make_pair(now);
  const std::vector<uint8_t> payload(static_cast<size_t>(state.range(0)), 0x5a);
  // Fresh signed messages, each checked once (a repeat is a replay).
  std::vector<std::vector<uint8_t>> messages(1000, payload);
  for (auto& message : messages) pair.sender.seal("X", message);
  size_t next = 0;
  int64_t refused = 0;
  for (auto _ : state) {
    if (next == messages.size()) {
      state.PauseTiming();
      for (auto& message : messages) {
        message = payload;
        pair.sender.seal("X", message);
      }
      next = 0;
      state.ResumeTiming();
    }
    const auto& message = messages[next++];
    refused += !pair.receiver.open("X", message.data(), message.size()).authentic;
  }
  state.counters["refused"] = static_cast<double>(refused);
  state.SetBytesProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_BusAuthOpen)->Arg(268)->Arg(23000)->Unit(benchmark::kMicrosecond);

}  // namespace
