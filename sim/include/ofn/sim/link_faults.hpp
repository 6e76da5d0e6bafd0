#pragma once
// A bad network for the lockstep runner: the three-host split of
// deploy/processes.yaml flown in one process, with every message that
// crosses from one host to another lost with the loss of any of its
// datagrams, and delayed by a fixed time plus a uniform jitter (so that
// messages also overtake one another). The draws come from a seeded
// generator in delivery order, so a faulty lockstep flight repeats to the
// bit, like a clean one.
//
// LCM sends a message of more than kShortMessageMax bytes as fragments of
// kFragmentPayload bytes, and a message is lost when any fragment is: a
// 9.6 KB scan is 7 datagrams and is lost 52 % of the time at 10 % loss.
// The services of one host share each message's fate (the datagrams are
// lost and held on the link, before the host), so the mapper and the RH
// optimiser on onboard2 see the same scans at the same time. Between the
// services of one host nothing happens unless `all_links` is set (the bus
// of one computer is not the radio between two, but a test may want the
// controller-vehicle loop delayed too).

#include <cstddef>
#include <cstdint>
#include <map>
#include <random>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/link_model.hpp"

namespace ofn::sim {

/// LCM 1.3.1 UDP multicast framing (lcm_udpm.c).
constexpr std::size_t kShortMessageMax = 1435;
constexpr std::size_t kFragmentPayload = 1423;

/// Datagrams LCM sends for a message of `bytes` bytes (channel name aside).
std::size_t datagrams_for(std::size_t bytes);

/// Which host each service runs on: the `processes:` table of
/// deploy/processes.yaml (name -> host). Throws ConfigError when unreadable.
std::map<std::string, std::string> load_service_hosts(const std::string& process_table);

struct LinkFaultsConfig {
  double datagram_loss = 0.0;  // probability, [0, 1)
  double delay = 0.0;          // s, every message
  double jitter = 0.0;         // s, uniform +- on top of the delay (never below 0)
  bool all_links = false;      // also between the services of one host
  std::uint64_t seed = 1;
  std::map<std::string, std::string> host_of;  // service -> host
};

class LinkFaults : public LinkModel {
 public:
  /// Throws std::invalid_argument for a probability outside [0, 1) or a
  /// negative or non-finite delay or jitter.
  explicit LinkFaults(LinkFaultsConfig config);
  ~LinkFaults() override;
  LinkFaults(const LinkFaults&) = delete;
  LinkFaults& operator=(const LinkFaults&) = delete;

  /// Subscribes to every channel of `lcm` to learn where one message ends
  /// and the next begins; call before any service subscribes, so that
  /// LCM hands each message to this first. `lcm` must outlive this.
  void watch(lcm::LCM& lcm);
  /// The message now being delivered is a new one: hosts draw afresh.
  void next_message() { decided_.clear(); }

  void published(const std::string& publisher, const std::string& channel) override;
  Delivery deliver(const std::string& receiver, const std::string& channel,
                   std::size_t bytes) override;

  /// Messages that crossed a faulty link, and of those the lost, per
  /// channel (a message reaching two hosts counts twice).
  struct ChannelCount {
    std::int64_t crossing = 0;
    std::int64_t lost = 0;
  };
  const std::map<std::string, ChannelCount>& counts() const { return counts_; }

  /// Host of `service`; throws std::out_of_range naming it when unknown.
  const std::string& host(const std::string& service) const;

 private:
  LinkFaultsConfig config_;
  std::mt19937_64 random_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  // Each channel has one publisher; a heartbeat channel its own service.
  std::map<std::string, std::string> publisher_;
  std::map<std::string, ChannelCount> counts_;
  // The fate of the message now being delivered, per receiving host (per
  // service with all_links: each then has its own link).
  std::map<std::string, Delivery> decided_;
  lcm::LCM* watched_ = nullptr;
  lcm::Subscription* subscription_ = nullptr;

  static void on_message(const lcm::ReceiveBuffer*, const std::string&, LinkFaults* self);
};

}  // namespace ofn::sim
