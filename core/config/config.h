#ifndef ROVER_CORE_CONFIG_CONFIG_H_
#define ROVER_CORE_CONFIG_CONFIG_H_

// Typed, validated YAML configuration.
//
// Every component owns an options struct with a static loader that reads its
// own section, in the spirit of Cartographer's LoadOptions:
//
//   struct ImuOptions {
//     double rate_hz = 0.0;
//     double gyro_noise_density_rad_s_sqrt_hz = 0.0;
//     Compression compression = Compression::kNone;
//
//     static ImuOptions Load(const ConfigNode& node) {
//       ImuOptions o;
//       o.rate_hz = node.GetInRange<double>("rate_hz", 100.0, 1000.0);
//       const ConfigNode noise = node.Child("noise");
//       o.gyro_noise_density_rad_s_sqrt_hz =
//           noise.GetInRange<double>("gyro_noise_density_rad_s_sqrt_hz", 0.0, 1.0);
//       o.compression = node.GetEnum<Compression>(
//           "compression", {{"none", Compression::kNone}, {"zstd", Compression::kZstd}},
//           Compression::kNone);
//       return o;
//     }
//   };
//
//   const ConfigNode root = ConfigNode::LoadFile(path);
//   const ImuOptions imu = ImuOptions::Load(root.Child("imu"));
//   root.CheckNoUnknownKeysRecursive();  // typos in optional keys are errors
//
// Every problem is reported as a ConfigError whose message starts with
// "file:line: full.key.path: ", e.g.
//   "rover.yaml:12: imu.rate_hz: expected a number in [100, 1000], found 5000".
// Lines are 1-based. Keys are single map keys, never dotted paths.
//
// Access tracking: every key read (or tested with Has) is recorded in state
// shared by all ConfigNodes of one document, so CheckNoUnknownKeys() can
// report keys that no loader consumed. ConfigNode is a cheap handle (copies
// share the state) and is not thread-safe; load configuration on one thread.

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace rover {

/// Any configuration problem: I/O, YAML syntax, missing or unknown key, wrong
/// type, out-of-range value. what() is "file:line: key.path: explanation".
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Name-to-value table for ConfigNode::GetEnum, e.g.
/// {{"zstd", Compression::kZstd}, {"lz4", Compression::kLz4}}.
template <typename E>
using EnumNames = std::initializer_list<std::pair<std::string_view, E>>;

namespace config_internal {

template <typename T>
struct IsStdVector : std::false_type {};
template <typename T, typename A>
struct IsStdVector<std::vector<T, A>> : std::true_type {};

template <typename T>
struct IsFixedEigenMatrix : std::false_type {};
template <typename S, int R, int C, int O, int MR, int MC>
struct IsFixedEigenMatrix<Eigen::Matrix<S, R, C, O, MR, MC>>
    : std::bool_constant<(R > 0 && C > 0)> {};

/// Integer types read from YAML integers. Character types are excluded:
/// `char c = 65` in a config file is almost certainly a mistake.
template <typename T>
concept Integer = std::integral<T> && !std::same_as<T, bool> && !std::same_as<T, char> &&
                  !std::same_as<T, wchar_t> && !std::same_as<T, char8_t> &&
                  !std::same_as<T, char16_t> && !std::same_as<T, char32_t>;

template <typename T>
concept Number = Integer<T> || std::same_as<T, double> || std::same_as<T, float>;

template <typename T>
concept Scalar = Number<T> || std::same_as<T, bool> || std::same_as<T, std::string>;

/// Every type ConfigNode::Get accepts.
template <typename T>
concept Value = Scalar<T> ||(IsStdVector<T>::value&& Scalar<typename T::value_type>) ||
                (IsFixedEigenMatrix<T>::value && Number<typename T::Scalar>);

}  // namespace config_internal

/// A map or list inside a loaded YAML document, with typed accessors that
/// validate as they read. Obtained from LoadFile/LoadString and then Child,
/// ChildList or Items.
class ConfigNode {
 public:
  /// Reads and parses the YAML file at `path`. Throws ConfigError if the file
  /// cannot be read, is not valid YAML ("path:line: YAML syntax error ..."),
  /// has a duplicate or non-string key in any map, or its top level is a
  /// scalar. An empty file is an empty map (every key takes its default).
  static ConfigNode LoadFile(const std::string& path);

  /// As LoadFile, for YAML text held in memory; `source_name` stands in for the
  /// file name in error messages.
  static ConfigNode LoadString(std::string_view yaml, std::string source_name);

  /// Returns the value of the required key `key` of this map, converted to T.
  /// T is one of: bool (true/false only), a signed or unsigned integer type
  /// (fractional and out-of-range values are rejected), double or float
  /// (NaN and infinities are rejected), std::string, std::vector of those
  /// (a YAML list), or a fixed-size Eigen::Matrix (see below). Quoted scalars
  /// are strings and are never accepted as numbers or booleans.
  ///
  /// Eigen vectors are read from a flat list of exactly N numbers. Matrices are
  /// read from a list of rows ([[1, 0], [0, 1]]) or from a flat list of R * C
  /// numbers in row-major order ([1, 0, 0, 1]); any other shape is an error.
  ///
  /// Throws ConfigError if the key is missing, or its value has the wrong type
  /// or is out of the range of T.
  template <config_internal::Value T>
  T Get(std::string_view key) const;

  /// As Get(key), but returns `default_value` if the key is absent. A key that
  /// is present but invalid (including `key:` with no value) is still an
  /// error, never silently replaced by the default. T must be spelled out:
  /// Get<double>("gain", 1).
  template <config_internal::Value T>
  T Get(std::string_view key, std::type_identity_t<T> default_value) const;

  /// As Get<T>(key) for a number, additionally requiring lo <= value <= hi.
  /// Error: "expected a number in [lo, hi], found <text>".
  template <config_internal::Number T>
  T GetInRange(std::string_view key, std::type_identity_t<T> lo, std::type_identity_t<T> hi) const;

  /// As GetInRange(key, lo, hi), but returns `default_value` if the key is
  /// absent. The default itself is not range-checked.
  template <config_internal::Number T>
  T GetInRange(std::string_view key, std::type_identity_t<T> lo, std::type_identity_t<T> hi,
               std::type_identity_t<T> default_value) const;

  /// As Get<double>(key), but also accepts .inf, -.inf and .nan, for the few
  /// options where they are meaningful (e.g. "no timeout").
  double GetAllowNonFinite(std::string_view key) const;

  /// Optional variant of GetAllowNonFinite(key).
  double GetAllowNonFinite(std::string_view key, double default_value) const;

  /// Returns the enumerator whose name equals the string value of the required
  /// key. Matching is exact (case-sensitive). The error for an unknown name
  /// lists all allowed names. E must be spelled out:
  /// GetEnum<Compression>("compression", {{"zstd", Compression::kZstd}}).
  template <typename E>
  E GetEnum(std::string_view key, EnumNames<E> names) const;

  /// Optional variant of GetEnum: returns `default_value` if the key is absent.
  template <typename E>
  E GetEnum(std::string_view key, EnumNames<E> names, std::type_identity_t<E> default_value) const;

  /// True if this map has the key. A present key counts as used for
  /// CheckNoUnknownKeys, so only call it for keys the caller understands.
  bool Has(std::string_view key) const;

  /// Returns the required map-valued key as a node. Throws ConfigError if the
  /// key is missing or its value is not a map (write `key: {}` for an empty
  /// map; a bare `key:` is null).
  ConfigNode Child(std::string_view key) const;

  /// Returns the elements of the required list-valued key, as nodes with paths
  /// "key[0]", "key[1]", ... Elements are typically maps (use Get on them).
  std::vector<ConfigNode> ChildList(std::string_view key) const;

  /// Returns the elements of this node, which must be a list (e.g. a top-level
  /// list, or an element of a list of lists).
  std::vector<ConfigNode> Items() const;

  /// Returns the keys of this map in file order, for maps whose keys are data
  /// (e.g. sensor name -> options). Does not mark them as used; reading them
  /// with Get/Child does.
  std::vector<std::string> Keys() const;

  /// Throws ConfigError listing, one per line with its own file:line, every
  /// key of this map that was not read by Get*, Child, ChildList or Has. Keys
  /// that look like a typo of a key the loader asked for (present or not) get
  /// a "did you mean" hint. Does nothing for a list.
  void CheckNoUnknownKeys() const;

  /// As CheckNoUnknownKeys, for this node and every map below it that is
  /// reachable through used keys and list elements. A used key whose value is
  /// a map nobody read from (e.g. only tested with Has) has all its keys
  /// reported. Call it on the root after all loaders ran.
  void CheckNoUnknownKeysRecursive() const;

  /// Throws a ConfigError located at `key` of this map (at this node itself if
  /// `key` is empty or absent), for validation that spans several values:
  /// node.Fail("max_speed_m_s", "must be greater than min_speed_m_s").
  [[noreturn]] void Fail(std::string_view key, std::string_view message) const;

  /// Full dotted path of this node from the document root, e.g.
  /// "cameras[1].intrinsics"; empty for the root.
  const std::string& Path() const { return path_; }

  /// "file:line: path" (or "file:line" for the root), where line is the
  /// 1-based line of the key that holds this node.
  std::string Where() const;

 private:
  struct Document;

  // A value inside the document together with what error messages need.
  struct Located {
    YAML::Node node;
    std::string path;
    int line = -1;  // 0-based as in YAML::Mark; -1 if unknown.
  };

  ConfigNode(std::shared_ptr<Document> doc, YAML::Node node, std::string path, int line);

  // Looks `key` up in this map, recording the query (for typo hints) and, if
  // found, the use. Throws if this node is not a map.
  std::optional<Located> Find(std::string_view key) const;
  Located Require(std::string_view key) const;
  ConfigNode MakeChild(const Located& value) const;
  std::vector<ConfigNode> MakeItems(const Located& list) const;

  template <typename T>
  T Convert(const Located& value) const;
  template <typename M>
  M ConvertMatrix(const Located& value) const;

  bool ToBool(const Located& value) const;
  int64_t ToInt(const Located& value, int64_t lo, int64_t hi) const;
  uint64_t ToUint(const Located& value, uint64_t hi) const;
  double ToDouble(const Located& value, bool allow_non_finite) const;
  float ToFloat(const Located& value) const;
  std::string ToString(const Located& value) const;
  std::string EnumText(const Located& value) const;
  std::vector<Located> ToElements(const Located& value) const;

  [[noreturn]] void Throw(const Located& at, std::string_view message) const;
  [[noreturn]] void ThrowRange(const Located& at, bool integer, const std::string& lo,
                               const std::string& hi) const;
  [[noreturn]] void ThrowEnum(const Located& at, const std::vector<std::string_view>& names) const;
  [[noreturn]] void ThrowShape(const Located& at, int rows, int cols, std::size_t found) const;

  static std::string NumberText(int64_t v);
  static std::string NumberText(uint64_t v);
  static std::string NumberText(double v);
  static std::string NumberText(float v);
  template <config_internal::Number T>
  T CheckRange(const Located& at, T value, T lo, T hi) const;

  // Appends (0-based line, message) for every unused key of `node` and, if
  // `recursive`, of the maps below its used keys. CheckUnknownKeys throws a
  // ConfigError listing them, if there are any.
  static void CollectUnknownKeys(const Document& doc, const YAML::Node& node,
                                 const std::string& path, bool recursive,
                                 std::vector<std::pair<int, std::string>>& out);
  void CheckUnknownKeys(bool recursive) const;

  std::shared_ptr<Document> doc_;
  YAML::Node node_;
  std::string path_;
  int line_ = -1;
};

// ---------------------------------------------------------------------------
// Template implementations.

template <config_internal::Value T>
T ConfigNode::Get(std::string_view key) const {
  return Convert<T>(Require(key));
}

template <config_internal::Value T>
T ConfigNode::Get(std::string_view key, std::type_identity_t<T> default_value) const {
  const std::optional<Located> value = Find(key);
  return value ? Convert<T>(*value) : default_value;
}

template <config_internal::Number T>
T ConfigNode::GetInRange(std::string_view key, std::type_identity_t<T> lo,
                         std::type_identity_t<T> hi) const {
  const Located value = Require(key);
  return CheckRange<T>(value, Convert<T>(value), lo, hi);
}

template <config_internal::Number T>
T ConfigNode::GetInRange(std::string_view key, std::type_identity_t<T> lo,
                         std::type_identity_t<T> hi, std::type_identity_t<T> default_value) const {
  const std::optional<Located> value = Find(key);
  return value ? CheckRange<T>(*value, Convert<T>(*value), lo, hi) : default_value;
}

template <typename E>
E ConfigNode::GetEnum(std::string_view key, EnumNames<E> names) const {
  const Located value = Require(key);
  const std::string text = EnumText(value);
  std::vector<std::string_view> allowed;
  for (const auto& [name, enumerator] : names) {
    if (name == text) return enumerator;
    allowed.push_back(name);
  }
  ThrowEnum(value, allowed);
}

template <typename E>
E ConfigNode::GetEnum(std::string_view key, EnumNames<E> names,
                      std::type_identity_t<E> default_value) const {
  return Has(key) ? GetEnum<E>(key, names) : default_value;
}

template <config_internal::Number T>
T ConfigNode::CheckRange(const Located& at, T value, T lo, T hi) const {
  // Written so that NaN bounds or values fail rather than pass.
  if (!(value >= lo && value <= hi)) {
    if constexpr (std::is_floating_point_v<T>) {
      ThrowRange(at, false, NumberText(lo), NumberText(hi));
    } else if constexpr (std::is_signed_v<T>) {
      ThrowRange(at, true, NumberText(static_cast<int64_t>(lo)),
                 NumberText(static_cast<int64_t>(hi)));
    } else {
      ThrowRange(at, true, NumberText(static_cast<uint64_t>(lo)),
                 NumberText(static_cast<uint64_t>(hi)));
    }
  }
  return value;
}

template <typename T>
T ConfigNode::Convert(const Located& value) const {
  namespace ci = config_internal;
  if constexpr (std::is_same_v<T, bool>) {
    return ToBool(value);
  } else if constexpr (std::is_same_v<T, std::string>) {
    return ToString(value);
  } else if constexpr (std::is_same_v<T, double>) {
    return ToDouble(value, /*allow_non_finite=*/false);
  } else if constexpr (std::is_same_v<T, float>) {
    return ToFloat(value);
  } else if constexpr (ci::Integer<T> && std::is_signed_v<T>) {
    return static_cast<T>(
        ToInt(value, std::numeric_limits<T>::min(), std::numeric_limits<T>::max()));
  } else if constexpr (ci::Integer<T>) {
    return static_cast<T>(ToUint(value, std::numeric_limits<T>::max()));
  } else if constexpr (ci::IsStdVector<T>::value) {
    T out;
    for (const Located& element : ToElements(value)) {
      out.push_back(Convert<typename T::value_type>(element));
    }
    return out;
  } else {
    static_assert(ci::IsFixedEigenMatrix<T>::value);
    return ConvertMatrix<T>(value);
  }
}

template <typename M>
M ConfigNode::ConvertMatrix(const Located& value) const {
  using S = typename M::Scalar;
  constexpr int kRows = M::RowsAtCompileTime;
  constexpr int kCols = M::ColsAtCompileTime;
  constexpr std::size_t kSize = static_cast<std::size_t>(kRows) * static_cast<std::size_t>(kCols);
  const std::vector<Located> elements = ToElements(value);
  M out;
  if (elements.size() == kSize && !elements.front().node.IsSequence()) {
    // Flat list, row-major (the order in which a matrix is read aloud).
    for (std::size_t i = 0; i < kSize; ++i) {
      out(static_cast<Eigen::Index>(i / kCols), static_cast<Eigen::Index>(i % kCols)) =
          Convert<S>(elements[i]);
    }
    return out;
  }
  const bool is_matrix = kRows > 1 && kCols > 1;
  if (!is_matrix || elements.size() != static_cast<std::size_t>(kRows) ||
      !elements.front().node.IsSequence()) {
    ThrowShape(value, kRows, kCols, elements.size());
  }
  for (std::size_t r = 0; r < elements.size(); ++r) {
    const std::vector<Located> row = ToElements(elements[r]);
    if (row.size() != static_cast<std::size_t>(kCols))
      ThrowShape(elements[r], 1, kCols, row.size());
    for (std::size_t c = 0; c < row.size(); ++c) {
      out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = Convert<S>(row[c]);
    }
  }
  return out;
}

}  // namespace rover

#endif  // ROVER_CORE_CONFIG_CONFIG_H_
