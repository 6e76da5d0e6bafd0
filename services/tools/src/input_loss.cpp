#include "ofn/tools/input_loss.hpp"

#include <algorithm>
#include <cstdio>

namespace ofn::report {
namespace {

SequenceCounts operator+(SequenceCounts a, const SequenceCounts& b) {
  a.received += b.received;
  a.lost += b.lost;
  a.duplicated += b.duplicated;
  a.unsequenced += b.unsequenced;
  a.publishers += b.publishers;
  return a;
}

SequenceCounts counts_of(const channel_counts_t& input) {
  SequenceCounts c;
  c.received = input.received;
  c.lost = input.lost;
  c.duplicated = input.duplicated;
  c.unsequenced = input.unsequenced;
  c.publishers = input.publishers;
  return c;
}

}  // namespace

int64_t sequenced_sent(const SequenceCounts& c) {
  return std::max<int64_t>(0, c.received - c.unsequenced - c.duplicated) + c.lost;
}

std::string describe(const InputTotal& input) {
  const SequenceCounts& c = input.counts;
  const int64_t sent = sequenced_sent(c);
  std::string text = input.service + " " + input.channel + ": " + std::to_string(c.lost) + " of " +
                     std::to_string(sent) + " lost";
  if (sent > 0) {
    char share[32];
    std::snprintf(share, sizeof share, " (%.1f %%)", 100.0 * static_cast<double>(c.lost) / sent);
    text += share;
  }
  if (c.duplicated > 0) text += ", " + std::to_string(c.duplicated) + " duplicated";
  return text;
}

std::vector<std::string> growth_lines(const std::vector<InputTotal>& grown) {
  std::vector<std::string> lines;
  const std::string* service = nullptr;
  for (const InputTotal& in : grown) {
    const SequenceCounts& c = in.counts;
    std::string part = in.channel + " +" + std::to_string(in.new_lost) + " lost (" +
                       std::to_string(c.lost) + " of " + std::to_string(sequenced_sent(c));
    if (const int64_t sent = sequenced_sent(c); sent > 0) {
      char share[32];
      std::snprintf(share, sizeof share, ", %.1f %%", 100.0 * static_cast<double>(c.lost) / sent);
      part += share;
    }
    part += ")";
    if (in.new_duplicated > 0) part += ", +" + std::to_string(in.new_duplicated) + " duplicated";
    if (service && *service == in.service) {
      lines.back() += "; " + part;
    } else {
      lines.push_back(in.service + ": " + part);
      service = &in.service;
    }
  }
  return lines;
}

SequenceCounts InputLossTally::Entry::total() const {
  return base + current;
}

void InputLossTally::heard(const heartbeat_t& heartbeat) {
  for (const auto& input : heartbeat.inputs) {
    const auto key = std::make_pair(heartbeat.service, input.channel);
    auto it = entries_.find(key);
    const SequenceCounts counts = counts_of(input);
    if (it == entries_.end()) {
      if (entries_.size() >= kMaxEntries) {
        ++ignored_;
        continue;
      }
      Entry entry;
      entry.pid = heartbeat.pid;
      entry.current = counts;
      entries_.emplace(key, entry);
      continue;
    }
    Entry& e = it->second;
    // A restarted process counts from zero again.
    if (heartbeat.pid != e.pid || counts.received < e.current.received) {
      e.base = e.base + e.current;
      e.pid = heartbeat.pid;
    }
    e.current = counts;
  }
}

std::vector<InputTotal> InputLossTally::totals() const {
  std::vector<InputTotal> out;
  out.reserve(entries_.size());
  for (const auto& [key, entry] : entries_) out.push_back({key.first, key.second, entry.total()});
  return out;
}

std::vector<InputTotal> InputLossTally::grown() {
  std::vector<InputTotal> out;
  for (auto& [key, entry] : entries_) {
    const SequenceCounts total = entry.total();
    if (total.lost <= entry.shown_lost && total.duplicated <= entry.shown_duplicated) continue;
    InputTotal input{key.first, key.second, total};
    input.new_lost = std::max<int64_t>(0, total.lost - entry.shown_lost);
    input.new_duplicated = std::max<int64_t>(0, total.duplicated - entry.shown_duplicated);
    entry.shown_lost = std::max(entry.shown_lost, total.lost);
    entry.shown_duplicated = std::max(entry.shown_duplicated, total.duplicated);
    out.push_back(std::move(input));
  }
  return out;
}

}  // namespace ofn::report
