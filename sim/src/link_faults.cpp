#include "ofn/sim/link_faults.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ofn/common/config.hpp"

namespace ofn::sim {

std::size_t datagrams_for(std::size_t bytes) {
  if (bytes <= kShortMessageMax) return 1;
  return (bytes + kFragmentPayload - 1) / kFragmentPayload;
}

std::map<std::string, std::string> load_service_hosts(const std::string& process_table) {
  YamlReader table = YamlReader::load_file(process_table);
  std::map<std::string, std::string> host_of;
  for (YamlReader& process : table.children("processes"))
    host_of[process.text("name")] = process.text("host");
  if (host_of.empty()) table.fail("processes", "lists no process");
  return host_of;
}

LinkFaults::LinkFaults(LinkFaultsConfig config)
    : config_(std::move(config)), random_(config_.seed) {
  if (!(config_.datagram_loss >= 0.0 && config_.datagram_loss < 1.0))
    throw std::invalid_argument("datagram loss must be in [0, 1)");
  if (!(config_.delay >= 0.0 && std::isfinite(config_.delay)) ||
      !(config_.jitter >= 0.0 && std::isfinite(config_.jitter)))
    throw std::invalid_argument("link delay and jitter must be finite and >= 0");
}

LinkFaults::~LinkFaults() {
  if (watched_) watched_->unsubscribe(subscription_);
}

void LinkFaults::on_message(const lcm::ReceiveBuffer*, const std::string&, LinkFaults* self) {
  self->next_message();
}

void LinkFaults::watch(lcm::LCM& lcm) {
  if (watched_) watched_->unsubscribe(subscription_);
  watched_ = &lcm;
  subscription_ = lcm.subscribeFunction(".*", &LinkFaults::on_message, this);
}

const std::string& LinkFaults::host(const std::string& service) const {
  const auto found = config_.host_of.find(service);
  if (found == config_.host_of.end())
    throw std::out_of_range("service '" + service + "' has no host in the process table");
  return found->second;
}

void LinkFaults::published(const std::string& publisher, const std::string& channel) {
  host(publisher);  // a service without a host is an error at once
  publisher_[channel] = publisher;
}

LinkModel::Delivery LinkFaults::deliver(const std::string& receiver, const std::string& channel,
                                        std::size_t bytes) {
  const auto from = publisher_.find(channel);
  // Published by no service (a test's own message): no link to cross.
  if (from == publisher_.end()) return {};
  const std::string& to = host(receiver);
  const bool same_host = host(from->second) == to;
  if (same_host && (!config_.all_links || from->second == receiver)) return {};
  // Every service of a host shares the fate; with all_links each service
  // on the publisher's host has a link of its own.
  const std::string& link = same_host ? receiver : to;
  const auto decided = decided_.find(link);
  if (decided != decided_.end()) return decided->second;
  ChannelCount& count = counts_[channel];
  ++count.crossing;
  Delivery fate;
  // Every fragment is drawn, lost or not, and the jitter always, so that
  // the sequence of draws does not depend on which fragment was lost.
  for (std::size_t i = datagrams_for(bytes); i > 0; --i)
    if (uniform_(random_) < config_.datagram_loss) fate.arrives = false;
  const double jitter = config_.jitter * (2.0 * uniform_(random_) - 1.0);
  fate.delay = std::max(0.0, config_.delay + jitter);
  if (!fate.arrives) ++count.lost;
  decided_.emplace(link, fate);
  return fate;
}

}  // namespace ofn::sim
