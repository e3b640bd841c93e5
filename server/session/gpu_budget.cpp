#include "gpu_budget.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string_view>

namespace fluidcast::server {
namespace {

// Weight of the newest sample: a change of cost is followed within about four samples.
constexpr double kNewestSampleWeight = 0.25;
constexpr double kLargestRise = 2.0;

}  // namespace

std::vector<double> share_equally(double budget, std::span<const double> demands) {
  std::vector<double> shares(demands.size(), 0.0);
  std::vector<std::size_t> order(demands.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return demands[a] < demands[b]; });
  double left = std::max(0.0, budget);
  for (std::size_t k = 0; k < order.size(); ++k) {
    // The smallest remaining demand is met when it fits under an equal split of what is left.
    const double level = left / double(order.size() - k);
    const double share = std::min(std::max(0.0, demands[order[k]]), level);
    shares[order[k]] = share;
    left -= share;
  }
  return shares;
}

std::vector<double> share_between_clients(double budget, std::span<const double> demands,
                                          std::span<const std::string> clients) {
  std::map<std::string_view, std::vector<std::size_t>> by_client;
  for (std::size_t k = 0; k < demands.size(); ++k) by_client[clients[k]].push_back(k);
  std::vector<double> client_demands;
  for (const auto& [client, members] : by_client) {
    double sum = 0.0;
    for (std::size_t k : members) sum += std::max(0.0, demands[k]);
    client_demands.push_back(sum);
  }
  const std::vector<double> client_shares = share_equally(budget, client_demands);
  std::vector<double> shares(demands.size(), 0.0);
  std::size_t c = 0;
  for (const auto& [client, members] : by_client) {
    std::vector<double> own;
    for (std::size_t k : members) own.push_back(demands[k]);
    const std::vector<double> own_shares = share_equally(client_shares[c++], own);
    for (std::size_t m = 0; m < members.size(); ++m) shares[members[m]] = own_shares[m];
  }
  return shares;
}

std::vector<GpuGrant> grant_gpu_time(double period_ms, double sim_share, double busy_share,
                                     std::span<const GpuDemand> demands) {
  std::vector<double> sim(demands.size()), render(demands.size());
  std::vector<std::string> clients(demands.size());
  std::map<std::string_view, std::size_t> watched_sessions;  // of each client with any watched
  for (std::size_t k = 0; k < demands.size(); ++k) {
    sim[k] = demands[k].sim_ms;
    render[k] = demands[k].render_ms;
    clients[k] = demands[k].client;
    if (demands[k].watched) ++watched_sessions[demands[k].client];
  }
  const auto others_watched = [&](const GpuDemand& demand) {
    const auto own = watched_sessions.find(demand.client);
    if (own == watched_sessions.end()) return watched_sessions.size();
    const std::size_t own_others = own->second - (demand.watched ? 1 : 0);
    return watched_sessions.size() - 1 + (own_others > 0 ? 1 : 0);
  };
  std::vector<double> sim_granted = share_between_clients(sim_share * period_ms, sim, clients);
  double sim_on_gpu = 0.0, render_wanted = 0.0;
  // Only GPU solvers take more: a CPU solver's steps take the worker thread's time, which the
  // tick's other work needs.
  std::vector<double> unmet_on_gpu(demands.size(), 0.0);
  for (std::size_t k = 0; k < demands.size(); ++k) {
    render_wanted += render[k];
    if (!demands[k].sim_on_gpu) continue;
    sim_on_gpu += sim_granted[k];
    unmet_on_gpu[k] = sim[k] - sim_granted[k];
  }
  const double spare = busy_share * period_ms - sim_on_gpu - render_wanted;
  if (spare > 0.0) {
    const std::vector<double> more = share_between_clients(spare, unmet_on_gpu, clients);
    for (std::size_t k = 0; k < demands.size(); ++k) {
      sim_granted[k] += more[k];
      sim_on_gpu += more[k];
    }
  }
  const std::vector<double> render_granted =
      share_between_clients(period_ms - sim_on_gpu, render, clients);
  std::vector<GpuGrant> grants(demands.size());
  for (std::size_t k = 0; k < demands.size(); ++k) {
    grants[k] = {sim_granted[k], render_granted[k], period_ms, others_watched(demands[k])};
  }
  return grants;
}

double GpuGrant::charge(double item_ms) const {
  return item_ms + double(others_watched) * std::max(0.0, item_ms - period_ms);
}

double FrameCharge::settle(double measured_ms) const {
  if (!std::isfinite(measured_ms) || measured_ms <= 0.0) return 0.0;
  // Past the cap the price stands if it was higher: the cap limits a debt, it refunds nothing.
  if (measured_ms > kMostMeasuredMs)
    return std::max(0.0, grant.charge(kMostMeasuredMs) - charged_ms);
  return grant.charge(measured_ms) - charged_ms;
}

void GpuAccount::deposit(double grant_ms, double dearest_item_ms) {
  balance_ms_ = std::min(balance_ms_ + grant_ms, grant_ms + std::max(0.0, dearest_item_ms));
}

int GpuAccount::affordable(double item_ms) const {
  // More than any step could use; keeps the count an int however small the item.
  constexpr double kMost = 1 << 20;
  if (!can_spend()) return 0;
  if (!(item_ms > 0.0)) return 1;
  return static_cast<int>(std::clamp(std::floor(balance_ms_ / item_ms), 1.0, kMost));
}

void CostEstimate::add(double ms) {
  if (!std::isfinite(ms) || ms <= 0.0) return;  // not a measurement: no work is free
  // One slow sample (a stall, a pipeline compiled on first use) counts as twice the estimate at
  // most: a real rise is followed within a few samples, a single outlier does not starve the item.
  if (known_) ms = std::min(ms, kLargestRise * ms_);
  ms_ = known_ ? (1.0 - kNewestSampleWeight) * ms_ + kNewestSampleWeight * ms : ms;
  known_ = true;
}

void CostEstimate::scale(double factor) {
  if (std::isfinite(factor) && factor > 0.0) ms_ *= factor;
}

double ClientDebts::left(const Debt& debt, double now_ms, double share) {
  const double forgiven = std::max(0.0, now_ms - debt.since_ms) * std::clamp(share, 0.0, 1.0);
  return std::max(0.0, debt.owed_ms - forgiven);
}

void ClientDebts::record(const std::string& client, double owed_ms, double now_ms) {
  if (!(owed_ms > 0.0)) return;
  const auto found = debts_.find(client);
  // Several sessions of one client ending: their debts add up (what is left of the older one,
  // counted as if the client had had the whole device meanwhile: the lenient side).
  const double earlier = found == debts_.end() ? 0.0 : left(found->second, now_ms, 1.0);
  debts_[client] = {earlier + owed_ms, now_ms};
  if (debts_.size() > kMostClients) {
    debts_.erase(std::min_element(debts_.begin(), debts_.end(), [](const auto& a, const auto& b) {
      return a.second.since_ms < b.second.since_ms;
    }));
  }
}

double ClientDebts::take(const std::string& client, double now_ms, double share) {
  const auto found = debts_.find(client);
  if (found == debts_.end()) return 0.0;
  const double owed = left(found->second, now_ms, share);
  debts_.erase(found);
  return owed;
}

}  // namespace fluidcast::server
