#include "optimize/cmaes.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "core/error.h"

namespace diverse {
namespace {

// Conditioning of C is capped here by adding to its diagonal (pycma's default
// stop criterion 'tolconditioncov' sits at the same value).
constexpr double kConditionCap = 1e14;
// Largest standard deviation sigma * sqrt(lambda_max(C)) allowed: samples stay
// finite and their squares too, so no objective sees an overflowing input.
constexpr double kMaxStd = 1e100;
// Smallest sigma (far below any tol_x); keeps sigma a normal double.
constexpr double kMinSigma = 1e-300;
// C is renormalized (C /= s, sigma *= sqrt(s), pc /= sqrt(s): the same
// distribution) when its largest eigenvalue leaves [1 / kMaxScaleC, kMaxScaleC].
constexpr double kMaxScaleC = 1e50;

constexpr const char* kStateFormat = "diverse.cmaes";
constexpr int kStateVersion = 1;

// --- Bit-exact doubles: hexadecimal floating point ("0x1.8p+1", "-inf", "nan").
std::string hex_double(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buffer[64];
  char* p = buffer;
  if (std::signbit(v)) *p++ = '-';
  *p++ = '0';
  *p++ = 'x';
  const auto result =
      std::to_chars(p, buffer + sizeof(buffer), std::fabs(v), std::chars_format::hex);
  return std::string(buffer, result.ptr);
}

// "cmaes state: FIELD: expected EXPECTATION".
[[noreturn]] void state_error(const std::string& field, const std::string& expectation) {
  throw_field_error("cmaes state", field, "expected " + expectation);
}

double parse_hex_double(const nlohmann::json& j, const std::string& field) {
  if (!j.is_string()) state_error(field, "a hexadecimal floating-point string");
  std::string_view s = j.get_ref<const std::string&>();
  if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
  if (s == "inf") return std::numeric_limits<double>::infinity();
  if (s == "-inf") return -std::numeric_limits<double>::infinity();
  bool negative = false;
  if (!s.empty() && s.front() == '-') {
    negative = true;
    s.remove_prefix(1);
  }
  if (s.size() < 3 || s[0] != '0' || (s[1] != 'x' && s[1] != 'X')) {
    state_error(field, "a hexadecimal floating-point string like \"0x1.8p+1\"");
  }
  s.remove_prefix(2);
  double v = 0;
  const auto result = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::hex);
  if (result.ec != std::errc() || result.ptr != s.data() + s.size()) {
    state_error(field, "a hexadecimal floating-point string like \"0x1.8p+1\"");
  }
  return negative ? -v : v;
}

std::string hex_u64(std::uint64_t v) {
  char buffer[32] = "0x";
  const auto result = std::to_chars(buffer + 2, buffer + sizeof(buffer), v, 16);
  return std::string(buffer, result.ptr);
}

std::uint64_t parse_hex_u64(const nlohmann::json& j, const std::string& field) {
  if (j.is_string()) {
    std::string_view s = j.get_ref<const std::string&>();
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
      s.remove_prefix(2);
      std::uint64_t v = 0;
      const auto result = std::from_chars(s.data(), s.data() + s.size(), v, 16);
      if (result.ec == std::errc() && result.ptr == s.data() + s.size()) return v;
    }
  }
  state_error(field, "a hexadecimal 64-bit integer string like \"0x1f\"");
}

nlohmann::json vector_json(const Eigen::VectorXd& v) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(hex_double(v[i]));
  return out;
}

// Matrices as a list of rows.
nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) out.push_back(vector_json(m.row(r).transpose()));
  return out;
}

// j[name]; `prefix` names the enclosing object in messages ("options.").
const nlohmann::json& field(const nlohmann::json& j, const std::string& name,
                            const std::string& prefix = "") {
  if (!j.is_object() || !j.contains(name)) {
    throw_field_error("cmaes state", prefix + name, "missing");
  }
  return j.at(name);
}

Eigen::VectorXd parse_vector(const nlohmann::json& j, const std::string& name, Eigen::Index size) {
  if (!j.is_array() || static_cast<Eigen::Index>(j.size()) != size) {
    state_error(name, "an array of " + std::to_string(size) + " numbers");
  }
  Eigen::VectorXd v(size);
  for (Eigen::Index i = 0; i < size; ++i) v[i] = parse_hex_double(j[i], name);
  return v;
}

Eigen::MatrixXd parse_matrix(const nlohmann::json& j, const std::string& name, Eigen::Index rows,
                             Eigen::Index cols) {
  if (!j.is_array() || static_cast<Eigen::Index>(j.size()) != rows) {
    state_error(name, "an array of " + std::to_string(rows) + " rows");
  }
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) m.row(r) = parse_vector(j[r], name, cols).transpose();
  return m;
}

template <typename T>
T parse_integer(const nlohmann::json& j, const std::string& name) {
  if (j.is_number_integer() &&
      !(j.is_number_unsigned() &&
        j.get<std::uint64_t>() > std::numeric_limits<std::uint64_t>::max() / 2)) {
    const long long v = j.get<long long>();
    if (v >= std::numeric_limits<T>::min() && v <= std::numeric_limits<T>::max()) {
      return static_cast<T>(v);
    }
  }
  state_error(name, "an integer");
}

bool parse_bool(const nlohmann::json& j, const std::string& name) {
  if (!j.is_boolean()) state_error(name, "true or false");
  return j.get<bool>();
}

void validate(const CmaesOptions& o, const Eigen::VectorXd& x0) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("CmaesOptions: " + what); };
  if (o.dim < 1) fail("dim must be >= 1, got " + std::to_string(o.dim));
  if (o.popsize != 0 && o.popsize < 2) {
    fail("popsize must be >= 2 (or 0 for the default), got " + std::to_string(o.popsize));
  }
  if (!(o.sigma0 > 0) || !std::isfinite(o.sigma0)) fail("sigma0 must be positive and finite");
  if (o.bounded && !(std::isfinite(o.lower) && std::isfinite(o.upper) && o.lower < o.upper)) {
    fail("bounds must be finite with lower < upper");
  }
  if (std::isnan(o.target_f)) fail("target_f must not be NaN");
  if (x0.size() != o.dim) {
    fail("x0 has " + std::to_string(x0.size()) + " entries, dim is " + std::to_string(o.dim));
  }
  if (!x0.allFinite()) fail("x0 must be finite");
}

}  // namespace

const char* to_string(StopReason reason) {
  switch (reason) {
    case StopReason::kNone: return "none";
    case StopReason::kTargetReached: return "target";
    case StopReason::kMaxEvaluations: return "max_evaluations";
    case StopReason::kMaxGenerations: return "max_generations";
    case StopReason::kTolFun: return "tol_fun";
    case StopReason::kTolX: return "tol_x";
    case StopReason::kConditionNumber: return "condition_number";
    case StopReason::kNoEffectAxis: return "no_effect_axis";
  }
  return "unknown";
}

Cmaes::Cmaes(const CmaesOptions& options, const Eigen::VectorXd& x0) : options_(options) {
  validate(options_, x0);
  set_constants();
  const int n = k_.n;
  mean_ = x0;
  sigma_ = options_.sigma0;
  ps_ = Eigen::VectorXd::Zero(n);
  pc_ = Eigen::VectorXd::Zero(n);
  C_ = Eigen::MatrixXd::Identity(n, n);
  B_ = Eigen::MatrixXd::Identity(n, n);
  D_ = Eigen::VectorXd::Ones(n);
  rng_ = Rng(options_.seed);
  best_x_ = to_box(mean_);
}

// Strategy constants, tutorial appendix A (Table 1, eqs. 48-58).
void Cmaes::set_constants() {
  const int n = options_.dim;
  const double nd = n;
  k_ = CmaesConstants{};
  k_.n = n;
  // (48): population size and parent number.
  k_.lambda = options_.popsize > 0 ? options_.popsize
                                   : 4 + static_cast<int>(std::floor(3.0 * std::log(nd)));
  k_.mu = k_.lambda / 2;
  const int lambda = k_.lambda;

  // (49): raw weights w'_i = ln((lambda + 1) / 2) - ln i, i = 1..lambda.
  Eigen::VectorXd raw(lambda);
  for (int i = 0; i < lambda; ++i) raw[i] = std::log((lambda + 1) / 2.0) - std::log(i + 1.0);
  double sum_pos = 0, sum_pos_sq = 0, sum_neg = 0, sum_neg_sq = 0;
  for (int i = 0; i < lambda; ++i) {
    if (raw[i] > 0) {
      sum_pos += raw[i];
      sum_pos_sq += raw[i] * raw[i];
    } else {
      sum_neg += raw[i];
      sum_neg_sq += raw[i] * raw[i];
    }
  }
  // Variance-effective selection masses (Table 1 caption).
  k_.mueff = sum_pos * sum_pos / sum_pos_sq;
  k_.mueff_minus = sum_neg_sq > 0 ? sum_neg * sum_neg / sum_neg_sq : 0.0;
  const double mueff = k_.mueff;

  // (55): step-size control.
  k_.cs = (mueff + 2) / (nd + mueff + 5);
  k_.damps = 1 + 2 * std::max(0.0, std::sqrt((mueff - 1) / (nd + 1)) - 1) + k_.cs;
  // (56)-(58): covariance matrix adaptation, alpha_cov = 2.
  const double alpha_cov = 2;
  k_.cc = (4 + mueff / nd) / (nd + 4 + 2 * mueff / nd);
  k_.c1 = alpha_cov / ((nd + 1.3) * (nd + 1.3) + mueff);
  k_.cmu = std::min(1 - k_.c1, alpha_cov * (mueff - 2 + 1 / mueff) /
                                   ((nd + 2) * (nd + 2) + alpha_cov * mueff / 2));
  // (54): learning rate of the mean.
  k_.cm = 1;

  // (50)-(53): positive weights sum to one; the negative ones are scaled so that
  // the decay of C vanishes (50), their mass respects mueff (51), and C stays
  // positive definite (52).
  double alpha_neg = 0;
  if (options_.active && sum_neg < 0) {
    const double alpha_mu_minus = 1 + k_.c1 / k_.cmu;                        // (50)
    const double alpha_mueff_minus = 1 + 2 * k_.mueff_minus / (mueff + 2);   // (51)
    const double alpha_posdef_minus = (1 - k_.c1 - k_.cmu) / (nd * k_.cmu);  // (52)
    alpha_neg = std::min({alpha_mu_minus, alpha_mueff_minus, alpha_posdef_minus});
  }
  k_.weights.resize(lambda);
  for (int i = 0; i < lambda; ++i) {
    k_.weights[i] = raw[i] >= 0 ? raw[i] / sum_pos : alpha_neg * raw[i] / -sum_neg;  // (53)
  }

  k_.chi_n = std::sqrt(nd) * (1 - 1 / (4 * nd) + 1 / (21 * nd * nd));
  // B and D need updating only every 1 / (10 n (c1 + c_mu)) generations, which
  // keeps the cost O(n^2) per sample (tutorial, appendix B on numerical effort).
  k_.lazy_gap = 1 / (10 * nd * (k_.c1 + k_.cmu));
  k_.history_length = 10 + static_cast<int>(std::ceil(30 * nd / lambda));
}

Eigen::VectorXd Cmaes::to_box(const Eigen::VectorXd& genotype) const {
  if (!options_.bounded) return genotype;
  const double lower = options_.lower, upper = options_.upper;
  const double width = upper - lower, period = 2 * width;
  Eigen::VectorXd x(genotype.size());
  for (Eigen::Index i = 0; i < genotype.size(); ++i) {
    double t = genotype[i] - lower;
    t -= period * std::floor(t / period);        // [0, period) up to rounding
    if (t > width) t = period - t;               // mirror the second half-period
    x[i] = std::clamp(lower + t, lower, upper);  // rounding only; never a real clip
  }
  return x;
}

Eigen::VectorXd Cmaes::mean() const { return to_box(mean_); }

void Cmaes::draw_candidates() {
  const int lambda = k_.lambda;
  // (39) y_k = B D z_k and (40) x_k = m + sigma y_k, for the z drawn in ask().
  Y_.noalias() = B_ * (D_.asDiagonal() * Z_);
  genotypes_.resize(lambda);
  candidates_.resize(lambda);
  for (int k = 0; k < lambda; ++k) {
    genotypes_[k] = mean_ + sigma_ * Y_.col(k);
    candidates_[k] = to_box(genotypes_[k]);
  }
}

const std::vector<Eigen::VectorXd>& Cmaes::ask() {
  if (pending_) throw std::logic_error("Cmaes::ask: the previous population was not told");
  const int n = k_.n, lambda = k_.lambda;
  // (38) z_k ~ N(0, I), drawn sample by sample, coordinate by coordinate.
  Z_.resize(n, lambda);
  for (int k = 0; k < lambda; ++k) {
    for (int i = 0; i < n; ++i) Z_(i, k) = rng_.normal();
  }
  draw_candidates();
  pending_ = true;
  return candidates_;
}

void Cmaes::tell(const std::vector<double>& fitness) {
  if (!pending_) throw std::logic_error("Cmaes::tell: no population was asked");
  const int n = k_.n, lambda = k_.lambda, mu = k_.mu;
  if (static_cast<int>(fitness.size()) != lambda) {
    throw std::invalid_argument("Cmaes::tell: expected " + std::to_string(lambda) +
                                " fitness values, got " + std::to_string(fitness.size()));
  }
  pending_ = false;
  evaluations_ += lambda;

  // Ranking: finite values ascending, then every non-finite one in index order.
  std::vector<int> order(lambda);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    const bool fa = std::isfinite(fitness[a]), fb = std::isfinite(fitness[b]);
    if (fa != fb) return fa;
    return fa && fitness[a] < fitness[b];
  });
  const double generation_best = std::isfinite(fitness[order[0]])
                                     ? fitness[order[0]]
                                     : std::numeric_limits<double>::infinity();
  if (generation_best < best_f_) {
    best_f_ = generation_best;
    best_x_ = candidates_[order[0]];
  }
  recent_best_.push_back(generation_best);
  if (static_cast<int>(recent_best_.size()) > k_.history_length) {
    recent_best_.erase(recent_best_.begin());
  }

  // Sorted steps y_{i:lambda} and their draws z_{i:lambda}.
  Eigen::MatrixXd Ys(n, lambda), Zs(n, lambda);
  for (int i = 0; i < lambda; ++i) {
    Ys.col(i) = Y_.col(order[i]);
    Zs.col(i) = Z_.col(order[i]);
  }
  const Eigen::VectorXd w_pos = k_.weights.head(mu);
  // (41) <y>_w = sum_{i<=mu} w_i y_{i:lambda}. With the decomposition used for
  // sampling, C^{-1/2} <y>_w = B <z>_w exactly.
  const Eigen::VectorXd y_w = Ys.leftCols(mu) * w_pos;
  const Eigen::VectorXd z_w = Zs.leftCols(mu) * w_pos;

  // (42) m <- m + c_m sigma <y>_w.
  mean_ += k_.cm * sigma_ * y_w;

  // (43) p_sigma <- (1 - c_sigma) p_sigma + sqrt(c_sigma (2 - c_sigma) mueff) C^{-1/2} <y>_w.
  ps_ = (1 - k_.cs) * ps_ + std::sqrt(k_.cs * (2 - k_.cs) * k_.mueff) * (B_ * z_w);
  const double ps_norm = ps_.norm();

  // h_sigma stalls the update of p_c while ||p_sigma|| is large (below (47)); the
  // generation counter g starts at 0.
  const double g1 = static_cast<double>(generation_ + 1);
  const bool h_sigma =
      ps_norm / std::sqrt(1 - std::pow(1 - k_.cs, 2 * g1)) < (1.4 + 2 / (n + 1.0)) * k_.chi_n;

  // (45) p_c <- (1 - c_c) p_c + h_sigma sqrt(c_c (2 - c_c) mueff) <y>_w.
  pc_ = (1 - k_.cc) * pc_;
  if (h_sigma) pc_ += std::sqrt(k_.cc * (2 - k_.cc) * k_.mueff) * y_w;

  // (46) w_i° = w_i for w_i >= 0, w_i n / ||C^{-1/2} y_{i:lambda}||^2 otherwise;
  // ||C^{-1/2} y|| = ||z|| for the decomposition the sample was drawn with.
  Eigen::VectorXd w_circ = k_.weights;
  for (int i = 0; i < lambda; ++i) {
    if (w_circ[i] < 0) {
      const double z2 = Zs.col(i).squaredNorm();
      w_circ[i] = z2 > 0 ? w_circ[i] * n / z2 : 0.0;
    }
  }

  // (47) C <- (1 + c1 delta(h_sigma) - c1 - c_mu sum w_j) C + c1 p_c p_c^T
  //           + c_mu sum_i w_i° y_{i:lambda} y_{i:lambda}^T,
  // delta(h_sigma) = (1 - h_sigma) c_c (2 - c_c).
  const double delta_h = h_sigma ? 0.0 : k_.cc * (2 - k_.cc);
  const double decay = 1 + k_.c1 * delta_h - k_.c1 - k_.cmu * k_.weights.sum();
  C_ *= decay;
  C_.noalias() += k_.c1 * pc_ * pc_.transpose();
  C_.noalias() += k_.cmu * (Ys * w_circ.asDiagonal()) * Ys.transpose();
  // Exact symmetry (the products above differ from it by rounding only).
  for (int j = 0; j < n; ++j) {
    for (int i = j + 1; i < n; ++i) C_(i, j) = C_(j, i);
  }

  // (44) sigma <- sigma exp(c_sigma / d_sigma (||p_sigma|| / E||N(0, I)|| - 1)); the
  // exponent is capped at 1 (a factor e per generation), which only matters when
  // p_sigma is many times its expected length.
  sigma_ *= std::exp(std::min(1.0, k_.cs / k_.damps * (ps_norm / k_.chi_n - 1)));

  // Keep the genotype mean within half a box width of the box (whole periods of
  // the reflection: no phenotype changes).
  if (options_.bounded) {
    const double width = options_.upper - options_.lower;
    const double centre = options_.lower + width / 2;
    for (int i = 0; i < n; ++i) {
      const double periods = std::round((mean_[i] - centre) / (2 * width));
      if (periods != 0) mean_[i] -= periods * 2 * width;
    }
  }

  ++generation_;
  update_eigensystem(false);
  limit_scales();
  stop_reason_ = check_stop(fitness);
}

void Cmaes::update_eigensystem(bool force) {
  if (!force && static_cast<double>(generation_ - eigen_generation_) <= k_.lazy_gap) return;
  eigen_generation_ = generation_;
  const int n = k_.n;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(C_, Eigen::ComputeEigenvectors);
  if (solver.info() != Eigen::Success || !solver.eigenvalues().allFinite() ||
      !solver.eigenvectors().allFinite() || !(solver.eigenvalues().maxCoeff() > 0)) {
    // Cannot happen with finite C; fall back to the last good decomposition.
    C_ = B_ * D_.array().square().matrix().asDiagonal() * B_.transpose();
    for (int j = 0; j < n; ++j) {
      for (int i = j + 1; i < n; ++i) C_(i, j) = C_(j, i);
    }
    return;
  }
  Eigen::VectorXd eigenvalues = solver.eigenvalues();  // ascending
  B_ = solver.eigenvectors();
  const double max_ev = eigenvalues[n - 1];
  const double min_ev = eigenvalues[0];
  condition_ = min_ev > 0 ? max_ev / min_ev : std::numeric_limits<double>::infinity();
  // Cap the condition number: C + delta I has the same eigenvectors.
  if (!(min_ev >= max_ev / kConditionCap)) {
    const double delta = max_ev / kConditionCap - min_ev;
    C_.diagonal().array() += delta;
    eigenvalues.array() += delta;
  }
  D_ = eigenvalues.cwiseMax(0.0).cwiseSqrt();
}

void Cmaes::limit_scales() {
  // Renormalize (sigma, C) -> (sigma sqrt(s), C / s): the same distribution, but
  // both stay far from overflow and underflow.
  const double max_ev = D_.maxCoeff() * D_.maxCoeff();
  if (max_ev > kMaxScaleC || max_ev < 1 / kMaxScaleC) {
    const double s = max_ev;
    C_ /= s;
    D_ /= std::sqrt(s);
    pc_ /= std::sqrt(s);
    sigma_ *= std::sqrt(s);
  }
  // sigma itself: no sample may overflow, and sigma stays a normal double.
  const double max_sigma = kMaxStd / D_.maxCoeff();
  if (!(sigma_ <= max_sigma)) sigma_ = max_sigma;
  if (!(sigma_ >= kMinSigma)) sigma_ = kMinSigma;
}

StopReason Cmaes::check_stop(const std::vector<double>& fitness) const {
  const CmaesOptions& o = options_;
  if (best_f_ <= o.target_f) return StopReason::kTargetReached;
  if (o.max_evaluations > 0 && evaluations_ >= o.max_evaluations) {
    return StopReason::kMaxEvaluations;
  }
  if (o.max_generations > 0 && generation_ >= o.max_generations) {
    return StopReason::kMaxGenerations;
  }
  if (o.tol_fun > 0 && static_cast<int>(recent_best_.size()) >= k_.history_length) {
    // Range of the recent best values and of the last generation's values.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    bool finite = true;
    auto take = [&](double f) {
      if (!std::isfinite(f)) finite = false;
      lo = std::min(lo, f);
      hi = std::max(hi, f);
    };
    for (double f : recent_best_) take(f);
    for (double f : fitness) take(f);
    if (finite && hi - lo < o.tol_fun) return StopReason::kTolFun;
  }
  if (o.tol_x > 0) {
    const double max_std = sigma_ * C_.diagonal().cwiseMax(0.0).cwiseSqrt().maxCoeff();
    const double max_pc = sigma_ * pc_.cwiseAbs().maxCoeff();
    if (max_std < o.tol_x && max_pc < o.tol_x) return StopReason::kTolX;
  }
  if (o.max_condition > 0 && condition_ > o.max_condition) return StopReason::kConditionNumber;
  // One principal axis per generation, in turn.
  const int axis = static_cast<int>(generation_ % k_.n);
  const Eigen::VectorXd moved = mean_ + 0.1 * sigma_ * D_[axis] * B_.col(axis);
  if (moved == mean_) return StopReason::kNoEffectAxis;
  return StopReason::kNone;
}

nlohmann::json Cmaes::to_json() const {
  const CmaesOptions& o = options_;
  nlohmann::json options = {
      {"dim", o.dim},
      {"popsize", o.popsize},
      {"sigma0", hex_double(o.sigma0)},
      {"seed", hex_u64(o.seed)},
      {"active", o.active},
      {"bounded", o.bounded},
      {"lower", hex_double(o.lower)},
      {"upper", hex_double(o.upper)},
      {"target_f", hex_double(o.target_f)},
      {"max_evaluations", o.max_evaluations},
      {"max_generations", o.max_generations},
      {"tol_fun", hex_double(o.tol_fun)},
      {"tol_x", hex_double(o.tol_x)},
      {"max_condition", hex_double(o.max_condition)},
  };
  const Rng::State& rs = rng_.state();
  nlohmann::json rng = {
      {"s", {hex_u64(rs.s[0]), hex_u64(rs.s[1]), hex_u64(rs.s[2]), hex_u64(rs.s[3])}},
      {"has_spare", rs.has_spare},
      {"spare", hex_double(rs.spare)},
  };
  nlohmann::json recent = nlohmann::json::array();
  for (double f : recent_best_) recent.push_back(hex_double(f));
  nlohmann::json state = {
      {"format", kStateFormat},
      {"version", kStateVersion},
      {"options", options},
      {"generation", generation_},
      {"evaluations", evaluations_},
      {"mean", vector_json(mean_)},
      {"sigma", hex_double(sigma_)},
      {"ps", vector_json(ps_)},
      {"pc", vector_json(pc_)},
      {"C", matrix_json(C_)},
      {"B", matrix_json(B_)},
      {"D", vector_json(D_)},
      {"condition", hex_double(condition_)},
      {"eigen_generation", eigen_generation_},
      {"rng", rng},
      {"recent_best", recent},
      {"best_x", vector_json(best_x_)},
      {"best_f", hex_double(best_f_)},
      {"stop_reason", to_string(stop_reason_)},
      // The draws of an asked but not yet told population (one row per sample).
      {"pending_z", pending_ ? matrix_json(Z_.transpose()) : nlohmann::json(nullptr)},
  };
  return state;
}

Cmaes Cmaes::from_json(const nlohmann::json& state) {
  if (!state.is_object()) throw_field_error("cmaes state", "", "expected a JSON object");
  if (!field(state, "format").is_string() || field(state, "format") != kStateFormat) {
    state_error("format", std::string("\"") + kStateFormat + "\"");
  }
  if (field(state, "version") != kStateVersion) {
    state_error("version", std::to_string(kStateVersion));
  }
  const nlohmann::json& jo = field(state, "options");
  CmaesOptions o;
  o.dim = parse_integer<int>(field(jo, "dim", "options."), "options.dim");
  o.popsize = parse_integer<int>(field(jo, "popsize", "options."), "options.popsize");
  o.sigma0 = parse_hex_double(field(jo, "sigma0", "options."), "options.sigma0");
  o.seed = parse_hex_u64(field(jo, "seed", "options."), "options.seed");
  o.active = parse_bool(field(jo, "active", "options."), "options.active");
  o.bounded = parse_bool(field(jo, "bounded", "options."), "options.bounded");
  o.lower = parse_hex_double(field(jo, "lower", "options."), "options.lower");
  o.upper = parse_hex_double(field(jo, "upper", "options."), "options.upper");
  o.target_f = parse_hex_double(field(jo, "target_f", "options."), "options.target_f");
  o.max_evaluations =
      parse_integer<long long>(field(jo, "max_evaluations", "options."), "options.max_evaluations");
  o.max_generations =
      parse_integer<long long>(field(jo, "max_generations", "options."), "options.max_generations");
  o.tol_fun = parse_hex_double(field(jo, "tol_fun", "options."), "options.tol_fun");
  o.tol_x = parse_hex_double(field(jo, "tol_x", "options."), "options.tol_x");
  o.max_condition =
      parse_hex_double(field(jo, "max_condition", "options."), "options.max_condition");
  if (o.dim < 1) state_error("options.dim", "an integer >= 1");

  Cmaes es;
  es.options_ = o;
  const Eigen::VectorXd mean = parse_vector(field(state, "mean"), "mean", o.dim);
  try {
    validate(o, mean);
  } catch (const std::invalid_argument& e) {
    throw_field_error("cmaes state", "options", e.what());
  }
  es.set_constants();
  const int n = es.k_.n, lambda = es.k_.lambda;
  es.mean_ = mean;
  es.generation_ = parse_integer<long long>(field(state, "generation"), "generation");
  es.evaluations_ = parse_integer<long long>(field(state, "evaluations"), "evaluations");
  es.sigma_ = parse_hex_double(field(state, "sigma"), "sigma");
  es.ps_ = parse_vector(field(state, "ps"), "ps", n);
  es.pc_ = parse_vector(field(state, "pc"), "pc", n);
  es.C_ = parse_matrix(field(state, "C"), "C", n, n);
  es.B_ = parse_matrix(field(state, "B"), "B", n, n);
  es.D_ = parse_vector(field(state, "D"), "D", n);
  es.condition_ = parse_hex_double(field(state, "condition"), "condition");
  es.eigen_generation_ =
      parse_integer<long long>(field(state, "eigen_generation"), "eigen_generation");
  if (!(es.sigma_ > 0) || !std::isfinite(es.sigma_)) state_error("sigma", "positive and finite");
  if (!es.ps_.allFinite() || !es.pc_.allFinite() || !es.C_.allFinite() || !es.B_.allFinite() ||
      !es.D_.allFinite()) {
    state_error("ps, pc, C, B, D", "finite numbers");
  }

  const nlohmann::json& jr = field(state, "rng");
  const nlohmann::json& js = field(jr, "s", "rng.");
  if (!js.is_array() || js.size() != 4) state_error("rng.s", "an array of 4 strings");
  Rng::State rs;
  for (int i = 0; i < 4; ++i) rs.s[i] = parse_hex_u64(js[i], "rng.s");
  rs.has_spare = parse_bool(field(jr, "has_spare", "rng."), "rng.has_spare");
  rs.spare = parse_hex_double(field(jr, "spare", "rng."), "rng.spare");
  es.rng_.set_state(rs);

  const nlohmann::json& jh = field(state, "recent_best");
  if (!jh.is_array() || static_cast<int>(jh.size()) > es.k_.history_length) {
    state_error("recent_best",
                "an array of at most " + std::to_string(es.k_.history_length) + " numbers");
  }
  for (const auto& f : jh) es.recent_best_.push_back(parse_hex_double(f, "recent_best"));
  es.best_x_ = parse_vector(field(state, "best_x"), "best_x", n);
  es.best_f_ = parse_hex_double(field(state, "best_f"), "best_f");

  const nlohmann::json& jstop = field(state, "stop_reason");
  bool known = false;
  for (int r = 0; r <= static_cast<int>(StopReason::kNoEffectAxis); ++r) {
    if (jstop.is_string() && jstop == to_string(static_cast<StopReason>(r))) {
      es.stop_reason_ = static_cast<StopReason>(r);
      known = true;
    }
  }
  if (!known) state_error("stop_reason", "a stop reason such as \"none\" or \"tol_fun\"");

  const nlohmann::json& jz = field(state, "pending_z");
  if (!jz.is_null()) {
    es.Z_ = parse_matrix(jz, "pending_z", lambda, n).transpose();
    es.draw_candidates();
    es.pending_ = true;
  }
  return es;
}

}  // namespace diverse
