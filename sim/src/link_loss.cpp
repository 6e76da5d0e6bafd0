#include "ofn/sim/link_loss.hpp"

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

LinkLoss::LinkLoss(LinkLossConfig config) : config_(std::move(config)), random_(config_.seed) {
  if (!(config_.datagram_loss >= 0.0 && config_.datagram_loss < 1.0))
    throw std::invalid_argument("datagram loss must be in [0, 1)");
}

const std::string& LinkLoss::host(const std::string& service) const {
  const auto found = config_.host_of.find(service);
  if (found == config_.host_of.end())
    throw std::out_of_range("service '" + service + "' has no host in the process table");
  return found->second;
}

LinkLoss::~LinkLoss() {
  if (watched_) watched_->unsubscribe(subscription_);
}

void LinkLoss::on_message(const lcm::ReceiveBuffer*, const std::string&, LinkLoss* self) {
  self->next_message();
}

void LinkLoss::watch(lcm::LCM& lcm) {
  if (watched_) watched_->unsubscribe(subscription_);
  watched_ = &lcm;
  subscription_ = lcm.subscribeFunction(".*", &LinkLoss::on_message, this);
}

void LinkLoss::published(const std::string& publisher, const std::string& channel) {
  publisher_host_[channel] = host(publisher);
}

bool LinkLoss::delivers(const std::string& receiver, const std::string& channel,
                        std::size_t bytes) {
  const auto from = publisher_host_.find(channel);
  // Published by no service (a test's own message): no link to cross.
  const std::string& to = host(receiver);
  if (from == publisher_host_.end() || from->second == to) return true;
  const auto decided = decided_.find(to);
  if (decided != decided_.end()) return decided->second;
  ChannelCount& count = counts_[channel];
  ++count.crossing;
  bool arrived = true;
  // Every fragment is drawn, lost or not, so that the sequence of draws
  // does not depend on which fragment was lost first.
  for (std::size_t i = datagrams_for(bytes); i > 0; --i)
    if (uniform_(random_) < config_.datagram_loss) arrived = false;
  if (!arrived) ++count.lost;
  decided_.emplace(to, arrived);
  return arrived;
}

}  // namespace ofn::sim
