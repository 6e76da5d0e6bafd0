#include "ofn/common/node.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <climits>
#include <mutex>
#include <random>

#include "ofn/common/channels.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/heartbeat_t.hpp"

namespace ofn {
namespace {

// What each LCM handle carries for the nodes made on it: set up by main()
// (an authenticator) or the lockstep runner (a simulated link) before any
// node exists, read by every node's constructor.
template <class T>
class PerHandle {
 public:
  void set(const lcm::LCM& lcm, std::shared_ptr<T> value) {
    std::lock_guard<std::mutex> lock(mutex_);
    by_handle_[&lcm] = std::move(value);
  }
  void erase(const lcm::LCM& lcm) {
    std::lock_guard<std::mutex> lock(mutex_);
    by_handle_.erase(&lcm);
  }
  std::shared_ptr<T> of(const lcm::LCM& lcm) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = by_handle_.find(&lcm);
    return found == by_handle_.end() ? nullptr : found->second;
  }

 private:
  std::mutex mutex_;
  std::map<const lcm::LCM*, std::shared_ptr<T>> by_handle_;
};

PerHandle<bus_auth::Authenticator>& authenticators() {
  static PerHandle<bus_auth::Authenticator> registry;
  return registry;
}

PerHandle<LinkModel>& links() {
  static PerHandle<LinkModel> registry;
  return registry;
}

// splitmix64's finaliser: every input bit moves every output bit.
uint64_t mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Drawn once per process: two runs of a service, or two processes, differ.
uint64_t process_nonce() {
  static const uint64_t nonce = [] {
    std::random_device device;
    const uint64_t drawn = (static_cast<uint64_t>(device()) << 32) ^ device();
    return mix(drawn ^ mix(static_cast<uint64_t>(::getpid())) ^
               static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()));
  }();
  return nonce;
}

uint64_t make_publisher_id(const std::string& name, const Clock& clock) {
  // The order nodes are made in tells two nodes of one name apart (a test
  // that restarts a service in one process).
  static std::atomic<uint64_t> made{0};
  const uint64_t order = made.fetch_add(1);
  uint64_t id = clock.deterministic() ? mix(static_cast<uint64_t>(clock.now())) : process_nonce();
  for (unsigned char c : name) id = mix(id ^ c);
  id = mix(id ^ order);
  return id == 0 ? 1 : id;
}

}  // namespace

void attach_link_model(lcm::LCM& lcm, std::shared_ptr<LinkModel> link) {
  links().set(lcm, std::move(link));
}

void detach_link_model(lcm::LCM& lcm) {
  links().erase(lcm);
}

void attach_authenticator(lcm::LCM& lcm, std::shared_ptr<bus_auth::Authenticator> authenticator) {
  authenticators().set(lcm, std::move(authenticator));
}

void detach_authenticator(lcm::LCM& lcm) {
  authenticators().erase(lcm);
}

std::string heartbeat_channel(const std::string& service) {
  std::string channel = channels::kHeartbeatPrefix;
  for (char c : service) channel += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return channel;
}

Node::Node(std::string name, lcm::LCM& lcm, const Clock& clock)
    : name_(std::move(name)),
      lcm_(lcm),
      clock_(clock),
      auth_(authenticators().of(lcm)),
      link_(links().of(lcm)),
      publisher_id_(make_publisher_id(name_, clock)),
      log_(make_logger(name_)),
      period_start_(std::chrono::steady_clock::now()) {
  // A keyring whose policy forgets this service's heartbeat is found at
  // start, not a second later by the first heartbeat.
  if (auth_ && !auth_->may_publish(heartbeat_channel(name_)))
    throw bus_auth::KeyError("role '" + auth_->role() + "' may not publish on " +
                             heartbeat_channel(name_) + " (the keyring's policy.yaml): service " +
                             name_ + " is not on that host");
  add_timer(
      1.0, [this] { publish_heartbeat(); }, "heartbeat");
}

Node::~Node() {
  for (auto& sub : subscriptions_)
    if (sub->handle) lcm_.unsubscribe(sub->handle);
}

void Node::on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Subscription* sub) {
  Node& node = *sub->node;
  if (node.link_) {
    // A simulated link: the message may never arrive, or arrive later.
    const auto fate = node.link_->deliver(node.name_, channel, rbuf->data_size);
    if (!fate.arrives) return;
    if (fate.delay > 0.0 && node.clock_.valid()) {
      const auto* bytes = static_cast<const uint8_t*>(rbuf->data);
      // After those due at the same time: they arrived first.
      node.held_.emplace(node.clock_.timer_now() + to_utime(fate.delay),
                         HeldMessage{sub, std::vector<uint8_t>(bytes, bytes + rbuf->data_size)});
      return;
    }
  }
  node.deliver_now(sub, rbuf);
}

void Node::deliver_now(Subscription* sub, const lcm::ReceiveBuffer* rbuf) {
  const auto begin = std::chrono::steady_clock::now();
  sub->deliver(rbuf);
  account_work(std::chrono::steady_clock::now() - begin);
}

void Node::deliver_held(Utime now) {
  while (!held_.empty() && held_.begin()->first <= now) {
    HeldMessage m = std::move(held_.begin()->second);
    held_.erase(held_.begin());
    lcm::ReceiveBuffer rbuf{m.bytes.data(), static_cast<uint32_t>(m.bytes.size()), now};
    deliver_now(m.sub, &rbuf);
  }
}

void Node::add_subscription(std::unique_ptr<Subscription> sub) {
  sub->handle = lcm_.subscribeFunction(sub->channel, &Node::on_raw, sub.get());
  subscriptions_.push_back(std::move(sub));
}

SequenceTracker* Node::track_input(const std::string& channel) {
  const auto [it, added] = sequences_.try_emplace(channel);
  return added ? &it->second : nullptr;
}

std::map<std::string, SequenceCounts> Node::input_counts() const {
  std::map<std::string, SequenceCounts> counts;
  for (const auto& [channel, tracker] : sequences_) counts.emplace(channel, tracker.counts());
  return counts;
}

bool Node::check_time(const std::string& channel, Utime stamp, const SubscribeOptions& options) {
  if (!clock_.valid()) return true;  // nothing to compare with yet
  const Utime now = clock_.now();
  if (options.max_future > 0 && stamp > now + to_utime(options.max_future)) {
    reject(channel, "stamped " + std::to_string(to_seconds(stamp - now)) + " s in the future");
    return false;
  }
  // Compared without `now - stamp`, which overflows for a stamp near
  // INT64_MIN (and then passed as fresh).
  if (options.max_age > 0 && stamp < now - to_utime(options.max_age)) {
    ++counters_.late;
    const double age = (static_cast<double>(now) - static_cast<double>(stamp)) * 1e-6;
    reject(channel, "stale by " + std::to_string(age) + " s");
    return false;
  }
  return true;
}

std::string reject_kind(const std::string& reason) {
  // Every run of number characters that holds a digit becomes '#'.
  static const std::string kNumberChars = "0123456789.+-eE";
  std::string kind;
  size_t i = 0;
  while (i < reason.size()) {
    size_t j = i;
    bool digit = false;
    while (j < reason.size() && kNumberChars.find(reason[j]) != std::string::npos) {
      digit = digit || std::isdigit(static_cast<unsigned char>(reason[j]));
      ++j;
    }
    if (j > i && digit) {
      kind += '#';
      i = j;
    } else if (j > i) {
      kind.append(reason, i, j - i);
      i = j;
    } else {
      kind += reason[i++];
    }
  }
  return kind;
}

void Node::reject(const std::string& channel, const std::string& reason) {
  ++counters_.rejected;
  counters_.last_reject_reason = channel + ": " + reason;
  // Counted by kind, in a bounded table: a flood of distinct reasons (every
  // stale stamp differs) must not grow the service's memory.
  const std::string kind = reject_kind(counters_.last_reject_reason);
  auto it = counters_.rejected_by_reason.find(kind);
  if (it != counters_.rejected_by_reason.end())
    ++it->second;
  else if (counters_.rejected_by_reason.size() < kMaxRejectKinds)
    counters_.rejected_by_reason.emplace(kind, 1);
  else
    ++counters_.rejected_by_reason[kOtherRejectKind];
  // One line per second at most, so a flood of bad input cannot flood the log.
  const Utime now = clock_.valid() ? clock_.timer_now() : 0;
  if (last_reject_log_ == INT64_MIN || now - last_reject_log_ >= kMicrosPerSecond ||
      now < last_reject_log_) {
    log_->warn(
        "rejected {} ({} total{})", counters_.last_reject_reason, counters_.rejected,
        suppressed_rejects_ ? ", " + std::to_string(suppressed_rejects_) + " not logged" : "");
    last_reject_log_ = now;
    suppressed_rejects_ = 0;
  } else {
    ++suppressed_rejects_;
  }
}

void Node::add_timer(double period, std::function<void()> callback, std::string label) {
  if (!(period > 0)) throw std::invalid_argument("timer '" + label + "': period must be > 0");
  Timer t;
  t.period = period;
  t.period_us = std::max<Utime>(1, to_utime(period));
  t.deadline = INT64_MIN;
  t.callback = std::move(callback);
  t.label = std::move(label);
  timers_.push_back(std::move(t));
}

Utime Node::next_deadline() const {
  Utime next = held_.empty() ? INT64_MAX : held_.begin()->first;
  // An unscheduled timer (INT64_MIN) is due at once.
  for (const auto& t : timers_) next = std::min(next, t.deadline);
  return next;
}

void Node::fire_due_timers() {
  if (!clock_.valid()) return;
  const Utime now = clock_.timer_now();
  deliver_held(now);
  if (start_time_ == INT64_MIN) start_time_ = now;
  for (auto& t : timers_) {
    if (t.deadline != INT64_MIN && t.deadline - now > t.period_us) {
      // Due more than a period ahead: the clock went back. Waiting for the
      // old deadline would silence the timer for as long as the step.
      log_->warn("timer '{}': the clock went back by about {:.3f} s; starting on its period afresh",
                 t.label, to_seconds(t.deadline - t.period_us - now));
      t.deadline = INT64_MIN;
    }
    if (t.deadline == INT64_MIN) {
      // Align to whole multiples of the period so that lockstep runs are
      // reproducible and rates line up across services.
      t.deadline = (now / t.period_us) * t.period_us;
      if (t.deadline < now) t.deadline += t.period_us;
    }
    if (t.deadline > now) continue;
    const auto begin = std::chrono::steady_clock::now();
    t.callback();
    account_work(std::chrono::steady_clock::now() - begin);
    // The periods missed beyond this one are not run: the same callback
    // at the same time again and again (up to a thousand after a jump of
    // the clock) only repeated what this call did.
    const Utime missed = (now - t.deadline) / t.period_us;
    t.deadline += (missed + 1) * t.period_us;
    if (missed > 0) {
      t.overruns += missed;
      if (missed * t.period_us >= kMicrosPerSecond)
        log_->warn(
            "timer '{}' fell {} periods ({:.3f} s) behind; fired once and kept to its "
            "period ({} missed in all)",
            t.label, missed, to_seconds(missed * t.period_us), t.overruns);
    }
  }
}

void Node::restart_timers() {
  for (auto& t : timers_) t.deadline = INT64_MIN;
}

void Node::account_work(std::chrono::steady_clock::duration busy) {
  const double s = std::chrono::duration<double>(busy).count();
  ++work_calls_;
  work_total_ += s;
  work_max_ = std::max(work_max_, s);
}

void Node::publish_heartbeat() {
  const auto wall_now = std::chrono::steady_clock::now();
  const double wall_period = std::chrono::duration<double>(wall_now - period_start_).count();
  heartbeat_t hb;
  hb.utime = clock_.now();
  hb.service = name_;
  hb.pid = static_cast<int32_t>(::getpid());
  hb.state = state_;
  hb.received = counters_.received;
  hb.rejected = counters_.rejected;
  hb.late = counters_.late;
  hb.unauthenticated = counters_.unauthenticated;
  hb.last_reject_reason = counters_.last_reject_reason;
  hb.loop_time_mean = work_calls_ ? work_total_ / static_cast<double>(work_calls_) : 0.0;
  hb.loop_time_max = work_max_;
  hb.cpu_fraction = wall_period > 0 ? work_total_ / wall_period : 0.0;
  hb.uptime = start_time_ == INT64_MIN ? 0.0 : to_seconds(clock_.timer_now() - start_time_);
  for (const auto& [channel, tracker] : sequences_) {
    const SequenceCounts& c = tracker.counts();
    channel_counts_t input;
    input.channel = channel;
    input.received = c.received;
    input.lost = c.lost;
    input.duplicated = c.duplicated;
    input.unsequenced = c.unsequenced;
    input.publishers = c.publishers;
    hb.inputs.push_back(std::move(input));
  }
  hb.num_inputs = static_cast<int32_t>(hb.inputs.size());
  publish(heartbeat_channel(name_), hb);
  work_calls_ = 0;
  work_total_ = 0.0;
  work_max_ = 0.0;
  period_start_ = wall_now;
}

}  // namespace ofn
