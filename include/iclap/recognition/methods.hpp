// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cctype>
#include <charconv>
#include <system_error>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/recognition/fusion.hpp"

namespace iclap {

/// A recognition method under a stable name (used on the command line and in
/// results files): a fusion expression, and whether the weights of its
/// top-level weighted sum are to be chosen by the brute-force grid
/// (`fit_weights`) or are fixed as written.
///
/// `alternatives` (beyond the paper) are further candidate expressions that
/// the cross validation chooses among, together with `fusion`, on the
/// training folds only, exactly as it chooses the weights: typically the
/// same expression over variants of a classifier with other settings (see
/// `with_variants`). With `fit_weights`, every candidate is a weighted sum
/// of as many terms as `fusion`, and the weights are chosen for each.
/// Distinct classifiers used by any of `fusions`, in first-use order.
inline std::vector<std::string> classifiers_of(const std::vector<Fusion>& fusions) {
  std::vector<std::string> out;
  for (const auto& f : fusions)
    for (const auto& c : f.classifiers())
      if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  return out;
}

struct Method {
  std::string name;
  Fusion fusion;
  bool fit_weights = false;
  std::vector<Fusion> alternatives;

  /// `fusion`, then the alternatives: the order in which ties are broken.
  std::vector<Fusion> candidates() const {
    std::vector<Fusion> out{fusion};
    out.insert(out.end(), alternatives.begin(), alternatives.end());
    return out;
  }
  /// Does the cross validation choose anything of this method on its
  /// training folds (weights or a candidate)?
  bool chosen_in_training() const noexcept { return fit_weights || !alternatives.empty(); }
  /// Distinct classifiers used by any candidate, in first-use order.
  std::vector<std::string> classifiers() const { return classifiers_of(candidates()); }
  /// Throws InvalidArgument naming "methods" when the weights are to be
  /// fitted but `fusion` is no weighted sum (a classifier alone, a product:
  /// nothing to weigh), or an alternative cannot take fitted weights like
  /// `fusion` (not a weighted sum of as many terms).
  void validate() const {
    if (!fit_weights) return;
    if (fusion.kind() != Fusion::Kind::WeightedSum)
      throw InvalidArgument("methods", "method '" + name + "' fits weights, but its fusion " + fusion.to_string() +
                                           " is not a weighted sum");
    for (const auto& a : alternatives)
      if (a.kind() != Fusion::Kind::WeightedSum || a.children().size() != fusion.children().size())
        throw InvalidArgument("methods", "method '" + name + "' fits weights, but its alternative " + a.to_string() +
                                             " is not a weighted sum of " + std::to_string(fusion.children().size()) +
                                             " terms");
  }
};

/// `m` with classifier `classifier` replaced by each of `variants` in turn
/// (e.g. "patch" by "patch-trim100", "patch-trim50"): one candidate per
/// variant and per candidate `m` already had, in that order, so applying it
/// for two classifiers gives every combination. The first candidate becomes
/// `fusion`, the rest `alternatives`; the name stays. A method that does not
/// use `classifier` is returned unchanged. Throws EmptyInput naming
/// "variants" for an empty list, and InvalidArgument naming "variants" for a
/// variant listed twice (two identical candidates) or, when `m` uses
/// `classifier`, one that is another classifier of `m` (a candidate with a
/// repeated term, "patch+icp" becoming "icp+icp"); `classifier` itself may
/// be one of its variants.
inline Method with_variants(const Method& m, const std::string& classifier, const std::vector<std::string>& variants) {
  if (variants.empty()) throw EmptyInput("variants", "no variant of classifier '" + classifier + "'");
  for (auto v = variants.begin(); v != variants.end(); ++v)
    if (std::find(variants.begin(), v, *v) != v)
      throw InvalidArgument("variants",
                            "'" + *v + "' is listed twice among the variants of classifier '" + classifier + "'");
  const auto used = m.classifiers();
  if (std::find(used.begin(), used.end(), classifier) == used.end()) return m;
  for (const auto& v : variants)
    if (v != classifier && std::find(used.begin(), used.end(), v) != used.end())
      throw InvalidArgument("variants", "'" + v + "', a variant of classifier '" + classifier +
                                            "', is already a classifier of method '" + m.name + "'");
  std::vector<Fusion> all;
  for (const auto& c : m.candidates())
    for (const auto& v : variants) all.push_back(c.renamed(classifier, v));
  Method out = m;
  out.fusion = all.front();
  out.alternatives.assign(all.begin() + 1, all.end());
  return out;
}

namespace detail {

/// `parts` joined by `separator`, in order.
inline std::string join(const std::vector<std::string>& parts, std::string_view separator) {
  std::string out;
  for (const auto& p : parts) {
    if (!out.empty()) out += separator;
    out += p;
  }
  return out;
}

/// `parts` sorted and joined by `separator` (the key of a commutative
/// operation).
inline std::string join_sorted(std::vector<std::string> parts, std::string_view separator) {
  std::sort(parts.begin(), parts.end());
  return join(parts, separator);
}

/// The text of `f` with the terms of every sum and the factors of every
/// product sorted, weights written exactly (method_key); `free_weights`:
/// the weights of this sum (fitted ones) are left out.
inline std::string fusion_key(const Fusion& f, bool free_weights) {
  switch (f.kind()) {
    case Fusion::Kind::Classifier: return f.name();
    case Fusion::Kind::WeightedSum: {
      // A sum of one term of weight 1 is that term ("1*icp" is "icp").
      if (f.children().size() == 1 && f.weights()[0] == 1.0) return fusion_key(f.children()[0], false);
      std::vector<std::string> terms;
      for (std::size_t i = 0; i < f.children().size(); ++i) {
        const std::string child = fusion_key(f.children()[i], false);
        const bool bracket = f.children()[i].kind() == Fusion::Kind::WeightedSum && child.find('+') != std::string::npos;
        const std::string term = bracket ? "(" + child + ")" : child;
        terms.push_back(free_weights ? term : format_exact(f.weights()[i]) + "*" + term);
      }
      return join_sorted(std::move(terms), "+");
    }
    case Fusion::Kind::Product: {
      std::vector<std::string> factors;
      for (const auto& c : f.children()) {
        const std::string child = fusion_key(c, false);
        factors.push_back(child.find('+') != std::string::npos ? "(" + child + ")" : child);
      }
      return join_sorted(std::move(factors), "*");
    }
  }
  return {};
}

/// Recursive-descent parser of method expressions:
///   sum     := term ('+' term)*
///   term    := [number '*'] product
///   product := factor ('*' factor)*
///   factor  := name | '(' sum ')'
class MethodParser {
 public:
  explicit MethodParser(const std::string& text) : s_(text) {}

  std::pair<Fusion, bool> parse() {
    bool fit = false;
    Fusion f = sum(fit);
    skip();
    if (pos_ != s_.size()) fail("unexpected " + quote_text(s_.substr(pos_), 40));
    return {f, fit};
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw InvalidArgument("method", quote_text(s_, 80) + ": " + why + " (at character " + std::to_string(pos_ + 1) + ")");
  }
  void skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool eat(char c) {
    skip();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }

  Fusion sum(bool& fit) {
    std::vector<std::pair<double, Fusion>> terms;
    int weighted = 0;
    do {
      skip();
      double w = 0;
      if (pos_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '.')) {
        const std::size_t start = pos_;
        const char* begin = s_.data() + pos_;
        // from_chars, not strtod: the same in every locale (a program that
        // set a decimal comma read "0.5*icp" as 0 followed by ".5"), and
        // no hex weights.
        const auto read = std::from_chars(begin, s_.data() + s_.size(), w);
        pos_ += static_cast<std::size_t>(read.ptr - begin);
        const std::size_t end = pos_;
        // A number is a weight only before '*': digits and letters ("3d",
        // and "2" or "1e5" with no '*' after them) name a classifier, as
        // Fusion::classifier takes them.
        const bool name_like = std::all_of(s_.begin() + static_cast<std::ptrdiff_t>(start),
                                           s_.begin() + static_cast<std::ptrdiff_t>(end),
                                           [](char c) { return is_name_char(c) || c == '-'; });
        if (pos_ < s_.size() && is_name_char(s_[pos_])) {
          pos_ = start;
          w = 0;
        } else if (!eat('*')) {
          if (!name_like) fail("a weight must be followed by '*'");
          pos_ = start;
          w = 0;
        } else {
          if (read.ec == std::errc::invalid_argument) fail("expected a weight before '*'");
          if (read.ec == std::errc::result_out_of_range)
            fail("the weight " + s_.substr(start, end - start) + " is out of the range of a double");
          ++weighted;
        }
      }
      terms.emplace_back(w, product());
    } while (eat('+'));
    if (terms.size() == 1 && weighted == 0) return terms.front().second;
    if (weighted != 0 && weighted != static_cast<int>(terms.size()))
      fail("give a weight for every term of a sum, or for none (then they are fitted)");
    // A term given twice: with fitted weights every split of their weight
    // gives the same fusion, so the grid's choice would mean nothing
    // ("icp+icp", a typo); with given weights w1 X + w2 X is (w1 + w2) X, so
    // "0.5*icp+0.5*icp" is icp again under another name, a second column of
    // one method.
    refuse_repeated(terms, [](const std::pair<double, Fusion>& t) -> const Fusion& { return t.second; }, "sum");
    if (weighted == 0) {
      // Weights to be chosen by the grid: start from uniform ones.
      fit = true;
      const double u = 1.0 / static_cast<double>(terms.size());
      for (auto& t : terms) t.first = u;
      double total = 0;
      for (std::size_t i = 0; i + 1 < terms.size(); ++i) total += terms[i].first;
      terms.back().first = 1.0 - total;
    }
    return Fusion::weighted_sum(std::move(terms));
  }

  Fusion product() {
    std::vector<Fusion> factors{factor()};
    while (eat('*')) factors.push_back(factor());
    // A factor given twice ranks the objects as it alone does ("icp*icp"),
    // also inside a bracketed product, which Fusion::product flattens
    // ("(icp*bow)*icp").
    std::vector<Fusion> flat;
    for (const Fusion& f : factors) {
      if (f.kind() == Fusion::Kind::Product) flat.insert(flat.end(), f.children().begin(), f.children().end());
      else flat.push_back(f);
    }
    refuse_repeated(flat, [](const Fusion& f) -> const Fusion& { return f; }, "product");
    return factors.size() == 1 ? factors.front() : Fusion::product(std::move(factors));
  }

  /// fail() naming the first item of `items` whose fusion (`fusion_of`)
  /// an earlier one has, up to the order of terms and factors (fusion_key,
  /// as method_key compares methods: "icp*bow" and "bow*icp" are one term).
  template <typename Item, typename FusionOf>
  void refuse_repeated(const std::vector<Item>& items, FusionOf fusion_of, const char* what) const {
    std::vector<std::string> keys;
    for (const Item& item : items) {
      std::string key = fusion_key(fusion_of(item), false);
      if (std::find(keys.begin(), keys.end(), key) != keys.end())
        fail(quote_text(fusion_of(item).to_string(), 40) + " appears twice in one " + what +
             "; give each classifier (or bracketed term) once");
      keys.push_back(std::move(key));
    }
  }

  Fusion factor() {
    if (eat('(')) {
      bool inner_fit = false;
      Fusion f = sum(inner_fit);
      if (inner_fit) fail("fitted weights are supported only in the top-level sum");
      if (!eat(')')) fail("missing ')'");
      return f;
    }
    skip();
    const std::size_t start = pos_;
    // Letters, digits, '_', and '-' after the first character: with_variants
    // names variants "patch-trim50".
    while (pos_ < s_.size() && (is_name_char(s_[pos_]) || (pos_ > start && s_[pos_] == '-'))) ++pos_;
    if (pos_ == start) fail("expected a classifier name");
    return Fusion::classifier(s_.substr(start, pos_ - start));
  }

  static bool is_name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

  std::string s_;
  std::size_t pos_ = 0;
};

}  // namespace detail

/// Parses a method: a classifier name ("iclap"), a sum whose weights are
/// fitted ("iclap+icp+bow"), a sum with fixed weights
/// ("0.6*iclap+0.2*icp+0.2*bow"), a product ("iclap*icp*bow") or any nesting
/// ("0.5*(icp*bow)+0.5*iclap"). A classifier name is letters, digits, '_'
/// and (not first) '-', as in with_variants' "patch-trim50"; a number is a
/// weight only before '*'. Spaces may separate tokens, not split a name or a
/// number. The method's name is `spec` with spaces removed. Throws
/// InvalidArgument naming "method" (syntax, with the position in `spec`) or
/// "weights" (bad fixed weights).
inline Method parse_method(const std::string& spec) {
  auto [fusion, fit] = detail::MethodParser(spec).parse();
  std::string name;
  for (char c : spec)
    if (!std::isspace(static_cast<unsigned char>(c))) name += c;
  return Method{name, std::move(fusion), fit, {}};
}


/// A text that two methods share exactly when they denote the same method
/// up to the order of the terms of a sum and of the factors of a product,
/// at any depth ("icp+bow" and "bow+icp", "iclap*icp" and "icp*iclap",
/// "0.4*bow+0.6*icp" and "0.6*icp+0.4*bow", "icp" and "1*icp"): fitted
/// weights are left out, fixed ones kept exactly, and the alternatives
/// follow in order. Other equal computations ("0.5*(0.5*a+0.5*b)+0.5*c" and
/// "0.25*a+0.25*b+0.5*c") keep distinct texts. For refusing a method list
/// that runs one method twice under two spellings.
inline std::string method_key(const Method& m) {
  std::string out = (m.fit_weights ? "fitted:" : "fixed:") + detail::fusion_key(m.fusion, m.fit_weights);
  for (const auto& a : m.alternatives) out += "|" + detail::fusion_key(a, m.fit_weights);
  return out;
}

/// The paper's eleven methods (Sections IV-VI), in its order: the three
/// single pipelines, the two decision fusions of ICP and BoW, and the six
/// hybrid fusions with iCLAP. `+` is a weighted sum whose weights the grid
/// chooses (the paper's w_p1, w_p2, w_w3, and w_p4 / w_w4 of Eqs. (9) and
/// (11)-(13)), `*` a product (Eqs. (10) and (14)).
inline std::vector<Method> paper_methods() {
  std::vector<Method> out;
  for (const char* spec : {"bow", "icp", "iclap", "icp+bow", "icp*bow", "iclap+icp", "iclap*icp", "iclap+bow",
                           "iclap*bow", "iclap+icp+bow", "iclap*icp*bow"})
    out.push_back(parse_method(spec));
  return out;
}

/// Whether `steps` steps leave any weight vector: at least one step, and a
/// step for each of `terms` weights unless weights may be 0.
inline bool weight_grid_has_room(int terms, int steps, bool zero_weights) noexcept {
  return steps >= 1 && (zero_weights || steps >= terms);
}

/// The most weight vectors a fitted method's grid may have: each is
/// evaluated on every inner-fold draw.
constexpr double kMaxWeightGrid = 1e6;

/// The number of vectors of weight_grid(terms, steps, zero_weights), as a
/// double (it can exceed any integer type): the compositions of `steps`
/// into `terms` parts, C(steps - 1, terms - 1), or C(steps + terms - 1,
/// terms - 1) when parts may be 0.
inline double weight_grid_size(int terms, int steps, bool zero_weights) noexcept {
  const double n = zero_weights ? static_cast<double>(steps) + terms - 1 : static_cast<double>(steps) - 1;
  double c = 1;
  for (int i = 1; i < terms; ++i) c = c * (n - (terms - 1) + i) / i;
  return c;
}

/// Throws InvalidArgument naming "weight_steps" when `steps` steps (with
/// `zero_weights`) leave no weight vector for the terms of `candidate`, a
/// fusion of method `method` whose weights are chosen on the grid, or give
/// it more than kMaxWeightGrid vectors: checked before a run, naming the
/// setting (weight_grid names its "steps", and builds any grid asked for).
inline void check_weight_steps(const std::string& method, const Fusion& candidate, int steps, bool zero_weights) {
  const std::size_t terms = candidate.children().size();
  const std::string of_method = " terms of method '" + method + "' (" + candidate.to_string() + ")";
  if (steps < 1) throw InvalidArgument("weight_steps", "must be at least 1, got " + std::to_string(steps));
  if (!weight_grid_has_room(static_cast<int>(terms), steps, zero_weights))
    throw InvalidArgument("weight_steps", "is " + std::to_string(steps) + ", fewer than the " + std::to_string(terms) +
                                              of_method + ", each weighted at least one step; raise it or allow zero weights");
  const double size = weight_grid_size(static_cast<int>(terms), steps, zero_weights);
  if (size > kMaxWeightGrid)
    throw InvalidArgument("weight_steps", "is " + std::to_string(steps) + ": the grid of the " + std::to_string(terms) +
                                              of_method + " has " + format_value(size) + " weight vectors, more than " +
                                              format_value(kMaxWeightGrid) + "; lower it");
}

/// The paper's brute-force weight grid: every vector of `terms` weights that
/// are multiples of 1/`steps` (0.1 for steps = 10), each at least one step,
/// summing to 1; in lexicographic order. 2 terms: 9 vectors (0.1..0.9);
/// 3 terms: 36. With `zero_weights` (beyond the paper) a weight may also be
/// 0, which drops that classifier: 2 terms: 11 vectors (0..1), 3 terms: 66.
/// Throws InvalidArgument naming "terms" / "steps" when no vector exists.
inline std::vector<std::vector<double>> weight_grid(int terms, int steps = 10, bool zero_weights = false) {
  if (terms < 1) throw InvalidArgument("terms", "must be at least 1, got " + std::to_string(terms));
  if (steps < 1) throw InvalidArgument("steps", "must be at least 1, got " + std::to_string(steps));
  if (!weight_grid_has_room(terms, steps, zero_weights))
    throw InvalidArgument("steps", "must be at least the number of terms (" + std::to_string(terms) + ")");
  const int least = zero_weights ? 0 : 1;
  std::vector<std::vector<double>> out;
  std::vector<int> parts(static_cast<std::size_t>(terms), least);
  // Enumerate compositions of `steps` into `terms` parts of at least `least`.
  auto rec = [&](auto&& self, int index, int left) -> void {
    if (index == terms - 1) {
      parts[static_cast<std::size_t>(index)] = left;
      std::vector<double> w;
      for (int p : parts) w.push_back(static_cast<double>(p) / static_cast<double>(steps));
      // Make the sum 1 despite rounding of the tenths, except for a last
      // weight of 0, which stays 0: 1 - total was -2.2e-16 for 5 terms of
      // tenths with zero weights, refused by Fusion as a negative weight.
      double total = 0;
      for (std::size_t i = 0; i + 1 < w.size(); ++i) total += w[i];
      if (parts.back() > 0) w.back() = 1.0 - total;
      out.push_back(std::move(w));
      return;
    }
    for (int p = least; p <= left - (terms - 1 - index) * least; ++p) {
      parts[static_cast<std::size_t>(index)] = p;
      self(self, index + 1, left - p);
    }
  };
  rec(rec, 0, steps);
  return out;
}

}  // namespace iclap
