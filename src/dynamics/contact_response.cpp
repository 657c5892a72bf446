#include "dynamics/contact_response.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "aloft/model.hpp"

namespace aloft {

namespace {

// The normal velocity (m/s, negative: closing) a contact may be left with: a gap of `distance` (m) may close
// within the step of h (s) but not pass it (a speculative contact); an overlap may not grow.
double closing_allowed(const Contact& c, double h) { return -std::max(c.distance, 0.0) / h; }

// An orthonormal basis (n, t1, t2) as matrix columns, t1 chosen away from n's largest component.
Mat3 contact_basis(const Vec3& n) {
  const Vec3 helper = std::abs(n.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 t1 = (helper - n.dot(helper) * n).normalized();
  Mat3 basis;
  basis.col(0) = n;
  basis.col(1) = t1;
  basis.col(2) = n.cross(t1);
  return basis;
}

// Velocity (m/s, world) of the point at `arm` from body's centre of mass; the fixed component 0 is still.
Vec3 point_velocity(int body, const Vec3& arm, const std::vector<Vec3>& velocity, const std::vector<Vec3>& angular) {
  return body == 0 ? Vec3::Zero() : Vec3(velocity[body] + angular[body].cross(arm));
}

// Whether the pair of components (a, b) comes before (c, d) in the order contacts are listed in (by the
// first component, then the second): the detector's order, which every list of contacts and pairs here
// keeps.
bool pair_before(int a, int b, int c, int d) { return a != c ? a < c : b < d; }

// Relative velocity of contact c's point on a with respect to b, world.
Vec3 relative_velocity(const Contact& c, const Vec3& arm_a, const Vec3& arm_b, const std::vector<Vec3>& velocity,
                       const std::vector<Vec3>& angular) {
  return point_velocity(c.a, arm_a, velocity, angular) - point_velocity(c.b, arm_b, velocity, angular);
}

}  // namespace

ContactResponse::ContactResponse(const Model& model)
    : model_(model),
      path_position_(model.count, -1),
      wrench_(model.count, Vec6::Zero()),
      du_(model.count, Vec6::Zero()),
      earlier_change_(model.count, Vec6::Zero()) {}

void ContactResponse::gather_wrenches(const std::vector<Contact>& contacts, const Eigen::VectorXd& P) {
  const int m = static_cast<int>(contacts.size());
  for (int k = 0; k < m; ++k) {
    const Vec3 impulse = basis_[k] * P.segment<3>(3 * k);
    const Contact& c = contacts[k];
    wrench_[c.a].head<3>() += impulse;
    wrench_[c.a].tail<3>() += arm_a_[k].cross(impulse);
    wrench_[c.b].head<3>() -= impulse;
    wrench_[c.b].tail<3>() -= arm_b_[k].cross(impulse);
  }
  // The solver ignores body 0 (fixed) and keeps every joint's velocity constraint (c = 0).
  wrench_[0].setZero();
  // Only the bodies touched above are non-zero (the elimination needs only their paths).
  touched_.clear();
  for (const Contact& c : contacts) touched_.push_back(c.a), touched_.push_back(c.b);
}

void ContactResponse::clear_wrenches(const std::vector<Contact>& contacts) {
  for (const Contact& c : contacts) {
    wrench_[c.a].setZero();
    wrench_[c.b].setZero();
  }
}

void ContactResponse::respond(const std::vector<Contact>& contacts, const Eigen::VectorXd& P) {
  gather_wrenches(contacts, P);
  solver_->solve_sparse(wrench_, touched_, du_);
  clear_wrenches(contacts);
}

// Contact c's gap (m) after two steps of h at its present normal approach speed (its gap now if it
// separates), at the pose its arms are measured from.
double ContactResponse::gap_after_two_steps_of(const Contact& c, const State& pose, double h,
                                               const std::vector<Vec3>& velocity, const std::vector<Vec3>& angular) {
  const double un = c.normal.dot(
      relative_velocity(c, c.point - pose.position[c.a], c.point - pose.position[c.b], velocity, angular));
  return c.distance + 2.0 * h * std::min(un, 0.0);
}

bool ContactResponse::closes_left_out(const State& pose, const std::vector<Contact>& found, double h,
                                      const std::vector<Vec3>& velocity, const std::vector<Vec3>& angular) const {
  if (found.size() != left_out_.size()) return false;
  for (std::size_t k = 0; k < found.size(); ++k)
    if (left_out_[k] && gap_after_two_steps_of(found[k], pose, h, velocity, angular) <= tuning.penetration_slop)
      return true;
  return false;
}

void ContactResponse::start_step() {
  pressing_.clear();
  carrying_.clear();
  carrying_step_ = 0;
}

void ContactResponse::step_taken() {
  const auto by_pair = [](const PressedPair& x, const PressedPair& y) { return pair_before(x.a, x.b, y.a, y.b); };
  std::sort(pressing_.begin(), pressing_.end(), by_pair);
  std::size_t kept = 0;  // one per pair, with its fastest approach
  for (const PressedPair& p : pressing_) {
    if (kept > 0 && pressing_[kept - 1].a == p.a && pressing_[kept - 1].b == p.b)
      pressing_[kept - 1].approach = std::max(pressing_[kept - 1].approach, p.approach);
    else
      pressing_[kept++] = p;
  }
  pressing_.resize(kept);
  std::swap(pressed_before_, pressed_last_);
  std::swap(pressed_last_, pressing_);
  pressing_.clear();
  std::swap(carried_, carrying_);
  carried_step_ = carrying_step_;
  carrying_.clear();
  carrying_step_ = 0;
}

bool ContactResponse::start_from_carried(const std::vector<Contact>& contacts, double h) {
  const int m = static_cast<int>(contacts.size());
  if (carried_.empty() || !(carried_step_ > 0)) return false;
  start_.setZero(3 * m);
  bool any = false;
  std::size_t j = 0;  // the first carried impulse not of a pair before contact k's (both sorted by (a, b))
  for (int k = 0; k < m; ++k) {
    const Contact& c = contacts[k];
    while (j < carried_.size() && pair_before(carried_[j].a, carried_[j].b, c.a, c.b)) ++j;
    const CarriedImpulse* nearest = nullptr;
    double nearest_distance = kCarriedReach;
    for (std::size_t i = j; i < carried_.size() && carried_[i].a == c.a && carried_[i].b == c.b; ++i) {
      const double distance = (carried_[i].point - c.point).norm();
      if (distance <= nearest_distance) {
        nearest = &carried_[i];
        nearest_distance = distance;
      }
    }
    if (!nearest) continue;
    Vec3 impulse = basis_[k].transpose() * nearest->impulse * (h / carried_step_);
    if (!(impulse.x() > 0)) continue;  // the normal turned: no guess
    const double friction = impulse.tail<2>().norm(), most = rows_[k].friction * impulse.x();
    if (friction > most) impulse.tail<2>() *= most / friction;  // into this contact's cone
    start_.segment<3>(3 * k) = impulse;
    any = true;
  }
  return any;
}

double ContactResponse::pressed_recently(int a, int b) const {
  const auto before = [](const PressedPair& p, std::pair<int, int> key) {
    return pair_before(p.a, p.b, key.first, key.second);
  };
  double fastest = -1;
  for (const std::vector<PressedPair>* step : {&pressed_last_, &pressed_before_}) {
    const auto it = std::lower_bound(step->begin(), step->end(), std::make_pair(a, b), before);
    if (it != step->end() && it->a == a && it->b == b) fastest = std::max(fastest, it->approach);
  }
  return fastest;
}

ContactStepReport ContactResponse::resolve(const State& pose, TreeSolver& solver,
                                           const std::vector<Contact>& found, double h,
                                           std::vector<Vec3>& velocity, std::vector<Vec3>& angular,
                                           std::vector<Vec6>& pseudo, bool& has_pseudo, bool again) {
  ContactStepReport report;
  has_pseudo = false;
  const bool after_earlier = again && has_earlier_change_;
  if (!again) has_earlier_change_ = false;
  if (!again) start_step();
  report.contacts = static_cast<int>(found.size());
  solver_ = &solver;

  // Keep the contacts that matter this step: touching or overlapping, or closing their gap within two
  // steps at their present approach speed. The detector's margin is a bound over every direction of
  // motion; most of what it reports cannot close, and each kept contact costs three tree solves.
  // At most kMaxContacts, the soonest to close first (the rest are looked at again next step).
  std::vector<Contact>& contacts = kept_;
  contacts.clear();
  closing_.clear();
  left_out_.assign(found.size(), 0);
  for (std::size_t k = 0; k < found.size(); ++k) {
    const Contact& c = found[k];
    const double gap_after_two_steps = gap_after_two_steps_of(c, pose, h, velocity, angular);
    if (c.distance > tuning.penetration_slop && gap_after_two_steps > tuning.penetration_slop) {
      left_out_[k] = 1;
      continue;
    }
    closing_.push_back({gap_after_two_steps, static_cast<int>(closing_.size())});
    contacts.push_back(c);
  }
  if (static_cast<int>(contacts.size()) > kMaxContacts) {
    std::vector<std::pair<double, int>> order = closing_;
    std::stable_sort(order.begin(), order.end());
    std::vector<Contact> soonest;
    for (int k = 0; k < kMaxContacts; ++k) soonest.push_back(contacts[order[k].second]);
    std::sort(soonest.begin(), soonest.end(), [](const Contact& x, const Contact& y) {
      return pair_before(x.a, x.b, y.a, y.b);
    });
    report.dropped = static_cast<int>(contacts.size()) - kMaxContacts;
    contacts = std::move(soonest);
  }
  const int m = static_cast<int>(contacts.size());
  if (m == 0) return report;
  report.solves = 1;
  report.solved = m;

  // Contact frames, lever arms and the velocities before the impulse (a relative to b, contact basis).
  basis_.resize(m);
  arm_a_.resize(m);
  arm_b_.resize(m);
  rows_.resize(m);
  u_.resize(3 * m);
  for (int k = 0; k < m; ++k) {
    const Contact& c = contacts[k];
    basis_[k] = contact_basis(c.normal);
    arm_a_[k] = c.point - pose.position[c.a];
    arm_b_[k] = c.point - pose.position[c.b];
    u_.segment<3>(3 * k) = basis_[k].transpose() * relative_velocity(c, arm_a_[k], arm_b_[k], velocity, angular);
    rows_[k].friction = 0.5 * (model_.friction[c.a] + model_.friction[c.b]);
    report.deepest = std::max(report.deepest, -c.distance);
    report.deepest_relative = std::max(report.deepest_relative, -c.distance / c.thinnest);
  }

  // The collision matrix K = G H^-1 G^T from path-sparse columns: each contact's three unit impulses
  // (along its basis) eliminated only along the paths from its two bodies to the base, and every 3x3 block
  // summed over the nodes two contacts' paths share. O(m depth) for the columns and O(m^2 depth) for the
  // blocks, instead of 3m full O(n) tree solves. What the last resolve at this factorization computed for
  // the same contacts is taken as it is (last_contacts_): the same numbers, bit for bit.
  std::swap(columns_, last_columns_);
  std::swap(K_, last_K_);
  const bool same_factorization =
      have_last_ && &solver == last_solver_ && solver.factorizations() == last_factorization_;
  same_as_last_.assign(static_cast<std::size_t>(m), -1);
  if (same_factorization) {
    // Both lists are sorted by (a, b) (the detector's order, kept by the kMaxContacts cut), so one merge.
    std::size_t j = 0;
    for (int k = 0; k < m; ++k) {
      const Contact& c = contacts[k];
      const auto before = [&](const Contact& q) { return pair_before(q.a, q.b, c.a, c.b); };
      while (j < last_contacts_.size() && before(last_contacts_[j])) ++j;
      for (std::size_t i = j; i < last_contacts_.size() && last_contacts_[i].a == c.a && last_contacts_[i].b == c.b; ++i) {
        const Contact& q = last_contacts_[i];
        if (q.point == c.point && q.normal == c.normal && last_arm_a_[i] == arm_a_[k] && last_arm_b_[i] == arm_b_[k]) {
          same_as_last_[static_cast<std::size_t>(k)] = static_cast<int>(i);
          break;
        }
      }
    }
  }
  if (static_cast<int>(columns_.size()) < m) columns_.resize(m);
  for (int k = 0; k < m; ++k) {
    const int was = same_as_last_[static_cast<std::size_t>(k)];
    if (was >= 0) {
      columns_[k] = last_columns_[static_cast<std::size_t>(was)];
      ++report.reused;
      continue;
    }
    const Contact& c = contacts[k];
    Mat63 on_a, on_b;
    on_a.topRows<3>() = basis_[k];
    on_a.bottomRows<3>() = skew(arm_a_[k]) * basis_[k];
    on_b.topRows<3>() = -basis_[k];
    on_b.bottomRows<3>() = -skew(arm_b_[k]) * basis_[k];
    solver.eliminate_on_paths(c.a, on_a, c.b, on_b, columns_[k]);
  }
  // Column by column of blocks: contact l's path marked in path_position_, each block above the
  // diagonal found by walking contact k's path alone (TreeSolver::coupling), or taken from the
  // last K where both contacts were there in the same order.
  K_.resize(3 * m, 3 * m);
  for (int l = 0; l < m; ++l) {
    const PathColumns& y = columns_[l];
    const int was_l = same_as_last_[static_cast<std::size_t>(l)];
    bool marked = false;
    for (int k = 0; k <= l; ++k) {
      const int was_k = same_as_last_[static_cast<std::size_t>(k)];
      // (Two contacts matched to one, were the list to hold a contact twice, are computed: the last K's
      // diagonal block is the transposed sum, not the same bits as the block between them.)
      if (was_k >= 0 && was_l >= 0 && (was_k < was_l || k == l)) {
        K_.block<3, 3>(3 * k, 3 * l) = last_K_.block<3, 3>(3 * was_k, 3 * was_l);
        K_.block<3, 3>(3 * l, 3 * k) = last_K_.block<3, 3>(3 * was_l, 3 * was_k);
        continue;
      }
      if (!marked) {
        for (std::size_t q = 0; q < y.node.size(); ++q) path_position_[static_cast<std::size_t>(y.node[q])] = static_cast<int>(q);
        marked = true;
      }
      const Mat3 block = TreeSolver::coupling(columns_[k], y, path_position_);
      K_.block<3, 3>(3 * k, 3 * l) = block;
      K_.block<3, 3>(3 * l, 3 * k) = block.transpose();
    }
    if (marked)
      for (int node : y.node) path_position_[static_cast<std::size_t>(node)] = -1;
  }
  last_contacts_.assign(contacts.begin(), contacts.end());
  last_arm_a_.assign(arm_a_.begin(), arm_a_.begin() + m);
  last_arm_b_.assign(arm_b_.begin(), arm_b_.begin() + m);
  last_solver_ = &solver;
  last_factorization_ = solver.factorizations();
  have_last_ = true;

  // Targets: bounce what collides fast within this step; let the rest close their gap but not pass it.
  const double threshold = std::max(tuning.bounce_threshold, 2.0 * model_.gravity.norm() * h);
  bool any_bounce = false;
  auto set_targets = [&](bool restitution) {
    for (int k = 0; k < m; ++k) {
      const Contact& c = contacts[k];
      const double un = u_[3 * k];
      const double e = 0.5 * (model_.restitution[c.a] + model_.restitution[c.b]);
      // (A pair pressed together bounces only when knocked: see start_step's declaration.)
      const bool collides =
          un < -threshold && c.distance + un * h <= 0 && -un > 2.0 * pressed_recently(c.a, c.b);
      rows_[k].target_normal = closing_allowed(c, h);
      if (restitution && collides && e > 0) {
        rows_[k].target_normal = -e * un;
        any_bounce = true;
      }
    }
  };
  set_targets(true);
  const bool warm = !again && start_from_carried(contacts, h);
  ContactLawResult law = solve_law(warm ? &start_ : nullptr);
  int sweeps = law.iterations;
  // Energy may only leave: allow round-off relative to the energies the impulses exchange.
  const auto gained = [&](const ContactLawResult& r) {
    const double scale = std::abs(u_.dot(P_)) + 1e-300;
    return r.energy_change > 1e-10 * scale;
  };
  if (any_bounce && gained(law)) {
    set_targets(false);
    law = solve_law(nullptr);
    sweeps += law.iterations;
    report.restitution_dropped = true;
  }
  // Block Gauss-Seidel with friction need not converge when the contacts' rows are nearly dependent (two
  // contacts between the same bodies, or a loop closed through a joint): on the shaken Steel Fish, with K's
  // smallest eigenvalue 1e-5 of its largest, it returned impulses of ~1 N s that added 0.2 J, and the
  // next halved steps flung a component at 1700 rad/s. Such a step is solved without friction and without
  // bounce (the normal law alone is a convex problem: it converges and only removes energy), and should
  // even that gain, with no impulse at all (the speculative targets try again next step).
  if (gained(law)) {
    set_targets(false);
    Eigen::VectorXd target(m);
    for (int k = 0; k < m; ++k) target[k] = rows_[k].target_normal;
    solve_frictionless_law(K_, u_(Eigen::seqN(0, m, 3)), target, P_);
    law.sticking = 0;
    law.sliding = 0;
    law.energy_change = contact_energy_change(K_, u_, P_);
    if (gained(law)) {
      P_.setZero();
      law.energy_change = 0;
    }
    report.friction_dropped = true;
    law.frictionless_contacts = m;
  }
  report.friction_dropped = report.friction_dropped || law.friction_dropped;
  report.frictionless = law.frictionless_contacts;
  report.iterations = sweeps;
  report.sticking = law.sticking;
  report.sliding = law.sliding;
  if (!again) carrying_step_ = h;
  for (int k = 0; k < m; ++k)
    if (P_[3 * k] > 0) {
      if (!again)
        carrying_.push_back({contacts[k].a, contacts[k].b, contacts[k].point, basis_[k] * P_.segment<3>(3 * k)});
      ++report.active;
      // The speed it was stopped from: a speculative contact (still apart) was only slowed to close its gap
      // within the step, and what it keeps of its approach was not stopped (counted, a ball slowed from 1.14
      // to 0.93 m/s before a knock then met that knock as pressed, and did not bounce).
      pressing_.push_back({contacts[k].a, contacts[k].b,
                           std::max(closing_allowed(contacts[k], h) - u_[3 * k], 0.0)});
    }
  // The law's energy change, u^T P + P^T K P / 2, is weighed at the half-kicked velocities u; the step's
  // is weighed at its start velocities u_start = u - (what the half kick did at the contact):
  // u_start^T P + P^T K P / 2 (see resolve's declaration).
  report.energy_change = law.energy_change;
  if (report.active > 0) {
    const auto start_velocity = [&](int body, const Vec3& arm) {
      if (body == 0) return Vec3(Vec3::Zero());
      Vec3 v = pose.velocity[body], w = pose.angular[body];
      if (after_earlier) {
        v += earlier_change_[body].head<3>();
        w += earlier_change_[body].tail<3>();
      }
      return Vec3(v + w.cross(arm));
    };
    for (int k = 0; k < m; ++k) {
      const Contact& c = contacts[k];
      const Vec3 u_start =
          basis_[k].transpose() * (start_velocity(c.a, arm_a_[k]) - start_velocity(c.b, arm_b_[k]));
      report.energy_change -= P_.segment<3>(3 * k).dot(u_.segment<3>(3 * k) - u_start);
    }
  }

  // Apply: one tree solve with G^T P gives every body's velocity change and the joint impulses.
  if (report.active > 0) {
    respond(contacts, P_);
    // Kept, summed over the step's resolves, for a later one's energy change (du_ is overwritten below
    // and by the contact passes): added to the earlier ones', or, for the step's first, taken by swapping.
    for (int i = 1; i < model_.count; ++i) {
      velocity[i] += du_[i].head<3>();
      angular[i] += du_[i].tail<3>();
      if (after_earlier) earlier_change_[i] += du_[i];
    }
    if (!after_earlier) {
      std::swap(earlier_change_, du_);
      has_earlier_change_ = true;
    }
  }

  // Split impulse: a frictionless pseudo-velocity that removes a part of each overlap beyond the slop.
  bool penetrating = false;
  Eigen::VectorXd target = Eigen::VectorXd::Zero(m);
  for (int k = 0; k < m; ++k) {
    const double overlap = -contacts[k].distance - tuning.penetration_slop;
    if (overlap > 0) {
      target[k] = std::min(tuning.penetration_rate * overlap, tuning.max_push) / h;
      penetrating = true;
    }
  }
  if (penetrating) {
    Eigen::VectorXd P;
    solve_frictionless_law(K_, Eigen::VectorXd::Zero(m), target, P);
    respond(contacts, P);
    for (int i = 0; i < model_.count; ++i) pseudo[i] = i == 0 ? Vec6::Zero() : du_[i];
    has_pseudo = true;
  }
  return report;
}

bool ContactResponse::correct(double h, std::vector<Vec3>& velocity, std::vector<Vec3>& angular,
                              double tolerance) {
  if (!solve_correction(h, velocity, angular, tolerance)) return false;
  apply_correction(velocity, angular);
  return true;
}

bool ContactResponse::solve_correction(double h, const std::vector<Vec3>& velocity, const std::vector<Vec3>& angular,
                                       double tolerance) {
  const std::vector<Contact>& contacts = kept_;
  const int m = static_cast<int>(contacts.size());
  if (m == 0) return false;
  bool needed = false;
  for (int k = 0; k < m; ++k) {
    const Contact& c = contacts[k];
    u_.segment<3>(3 * k) = basis_[k].transpose() * relative_velocity(c, arm_a_[k], arm_b_[k], velocity, angular);
    rows_[k].target_normal = closing_allowed(c, h);
    needed = needed || u_[3 * k] < rows_[k].target_normal - tolerance;
  }
  if (!needed) return false;
  solve_law(nullptr);
  return true;
}

void ContactResponse::apply_correction(std::vector<Vec3>& velocity, std::vector<Vec3>& angular) {
  respond(kept_, P_);
  for (int i = 1; i < model_.count; ++i) {
    velocity[i] += du_[i].head<3>();
    angular[i] += du_[i].tail<3>();
  }
}

ContactLawResult ContactResponse::solve_law(const Eigen::VectorXd* start) {
  const ContactLawResult result = solve_contact_law(K_, u_, rows_, P_, start);
  if (recorder_) {
    const int m = static_cast<int>(rows_.size());
    record_.K = K_;
    record_.u = u_;
    record_.target_normal.resize(m);
    record_.friction.resize(m);
    for (int k = 0; k < m; ++k) {
      record_.target_normal[k] = rows_[k].target_normal;
      record_.friction[k] = rows_[k].friction;
    }
    if (start) record_.start = *start;
    else record_.start.resize(0);
    record_.impulses = P_;
    recorder_(record_);
  }
  return result;
}

}  // namespace aloft
