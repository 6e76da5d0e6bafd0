#include "ofn/sim/lockstep.hpp"

#include <climits>
#include <stdexcept>

namespace ofn::sim {

Lockstep::Lockstep() : lcm_("memq://") {
  if (!lcm_.good()) throw std::runtime_error("cannot open memq:// LCM");
  lcm_.subscribeFunction(".*", &Lockstep::on_any, this);
}

void Lockstep::on_any(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Lockstep* self) {
  ++self->messages_;
  if (!self->log_) return;
  lcm::LogEvent e;
  e.eventnum = 0;
  e.timestamp = self->clock_.now();
  e.channel = channel;
  e.datalen = static_cast<int32_t>(rbuf->data_size);
  e.data = rbuf->data;
  self->log_->writeEvent(&e);
}

void Lockstep::record(const std::string& log_path) {
  log_ = std::make_unique<lcm::LogFile>(log_path, "w");
  if (!log_->good()) throw std::runtime_error("cannot write LCM log " + log_path);
}

void Lockstep::deliver_all() {
  // memq queues every publish; handle them all (handlers may publish more).
  while (lcm_.handleTimeout(0) > 0) {
  }
}

bool Lockstep::run(Utime end, const std::function<bool()>& stop) {
  deliver_all();
  while (true) {
    Utime next = INT64_MAX;
    for (Node* n : nodes_) next = std::min(next, n->next_deadline());
    if (next == INT64_MIN) next = clock_.now();  // timers not scheduled yet: start now
    if (next == INT64_MAX || next > end) return false;
    if (next > clock_.now()) clock_.set(next);
    for (Node* n : nodes_) n->fire_due_timers();
    deliver_all();
    ++steps_;
    if (stop && stop()) return true;
  }
}

}  // namespace ofn::sim
