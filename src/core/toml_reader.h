// A strict reader of one TOML table, shared by every file format we parse (task files,
// character files, skill files): unknown keys, wrong types, out-of-range or non-finite
// values and missing fields are one-line UserErrors "FILE: FIELD: expected ...", or
// "FILE: line N: FIELD: expected ..." from a reader made with_lines() (N the line of the
// key, or of its table when the key is missing).
#pragma once

#include <cmath>
#include <initializer_list>
#include <sstream>
#include <string>
#include <toml++/toml.h>
#include <vector>

#include "core/error.h"
#include "core/text_file.h"

namespace diverse {

// A number as messages print it (shortest form, as iostream writes it).
inline std::string num(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// Strict reader of one TOML table; `path` is the dotted name used in messages.
class TomlReader {
 public:
  TomlReader(std::string file, const toml::table& table, std::string path)
      : file_(std::move(file)), table_(table), path_(std::move(path)) {}

  // Rejects keys not in `known`.
  void only(std::initializer_list<const char*> known) const {
    for (const auto& [key, node] : table_) {
      bool ok = false;
      for (const char* k : known) ok = ok || key.str() == k;
      if (!ok) {
        std::string list;
        for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + k;
        fail(std::string(key.str()), "expected no such key (unknown key; known keys: " + list + ")");
      }
    }
  }
  bool has(const char* key) const { return table_.contains(key); }

  [[noreturn]] void fail(const std::string& key, const std::string& expectation) const {
    if (!lines_) throw_field_error(file_, field(key), expectation);
    const toml::node* n = table_.get(key);
    const auto line = (n != nullptr ? n->source() : table_.source()).begin.line;
    throw_field_error(file_ + ": line " + std::to_string(line), field(key), expectation);
  }
  // The same reader, naming the line in its messages (and its sub-readers').
  TomlReader with_lines() const {
    TomlReader r = *this;
    r.lines_ = true;
    return r;
  }
  std::string field(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  double number(const char* key, double lo, double hi) const {
    const toml::node* n = table_.get(key);
    const std::string expect = "expected a number in [" + num(lo) + ", " + num(hi) + "]";
    if (n == nullptr) fail(key, expect + " (missing)");
    double v = 0;
    if (auto f = n->as_floating_point()) {
      v = f->get();
    } else if (auto i = n->as_integer()) {
      v = static_cast<double>(i->get());
    } else {
      fail(key, expect);
    }
    if (!std::isfinite(v) || v < lo || v > hi) fail(key, expect + ", got " + num(v));
    return v;
  }
  double number(const char* key, double lo, double hi, double fallback) const {
    return has(key) ? number(key, lo, hi) : fallback;
  }
  long long integer(const char* key, long long lo, long long hi) const {
    const toml::node* n = table_.get(key);
    const std::string expect =
        "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (n == nullptr) fail(key, expect + " (missing)");
    auto i = n->as_integer();
    if (!i) fail(key, expect);
    const long long v = i->get();
    if (v < lo || v > hi) fail(key, expect + ", got " + std::to_string(v));
    return v;
  }
  long long integer(const char* key, long long lo, long long hi, long long fallback) const {
    return has(key) ? integer(key, lo, hi) : fallback;
  }
  std::string string(const char* key) const {
    const toml::node* n = table_.get(key);
    if (n == nullptr) fail(key, "expected a string (missing)");
    auto s = n->as_string();
    if (!s) fail(key, "expected a string");
    return s->get();
  }
  std::string string(const char* key, const std::string& fallback) const {
    return has(key) ? string(key) : fallback;
  }
  bool boolean(const char* key, bool fallback) const {
    if (!has(key)) return fallback;
    auto b = table_.get(key)->as_boolean();
    if (!b) fail(key, "expected true or false");
    return b->get();
  }
  const toml::table* table(const char* key, bool required) const {
    const toml::node* n = table_.get(key);
    if (n == nullptr) {
      if (required) fail(key, "expected a table (missing)");
      return nullptr;
    }
    if (!n->is_table()) fail(key, "expected a table");
    return n->as_table();
  }
  // An array of strings (`min` entries at least).
  std::vector<std::string> strings(const char* key, size_t min = 0) const {
    const toml::node* n = table_.get(key);
    const std::string expect = "expected an array of strings";
    if (n == nullptr) fail(key, expect + " (missing)");
    const toml::array* a = n->as_array();
    if (a == nullptr) fail(key, expect);
    std::vector<std::string> out;
    for (const toml::node& e : *a) {
      auto s = e.as_string();
      if (!s) fail(key, expect);
      out.push_back(s->get());
    }
    if (out.size() < min) fail(key, expect + " with at least " + std::to_string(min) + " entries");
    return out;
  }
  // An array of tables ([[key]]); empty when the key is absent and not required.
  std::vector<const toml::table*> tables(const char* key, bool required) const {
    const toml::node* n = table_.get(key);
    std::vector<const toml::table*> out;
    if (n == nullptr) {
      if (required) fail(key, "expected an array of tables ([[" + field(key) + "]]) (missing)");
      return out;
    }
    const toml::array* a = n->as_array();
    if (a == nullptr) fail(key, "expected an array of tables ([[" + field(key) + "]])");
    for (const toml::node& e : *a) {
      if (!e.is_table()) fail(key, "expected an array of tables ([[" + field(key) + "]])");
      out.push_back(e.as_table());
    }
    return out;
  }
  // A reader of entry `index` of an array of tables, named "key[index]" in messages.
  TomlReader element(const char* key, size_t index, const toml::table& t) const {
    TomlReader r(file_, t, field(key) + "[" + std::to_string(index) + "]");
    r.lines_ = lines_;
    return r;
  }
  TomlReader sub(const char* key, const toml::table& t) const {
    TomlReader r(file_, t, field(key));
    r.lines_ = lines_;
    return r;
  }
  // A reader of another table under the same name (a trimmed copy of this one's).
  TomlReader with_table(const toml::table& t) const {
    TomlReader r(file_, t, path_);
    r.lines_ = lines_;
    return r;
  }
  const toml::table& raw() const { return table_; }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }  // "constraints.landing", "" at the root

 private:
  std::string file_;
  const toml::table& table_;
  std::string path_;
  bool lines_ = false;
};

// Parses a TOML file; UserError "PATH: cannot read the WHAT file (REASON)" or "PATH: line N:
// expected valid TOML (...)".
inline toml::table parse_toml_file(const std::string& path, const std::string& what) {
  const std::string text = read_text_file(path, what);
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    std::string description(e.description());
    for (char& c : description)
      if (c == '\n' || c == '\r') c = ' ';
    throw UserError(path + ": line " + std::to_string(e.source().begin.line) +
                    ": expected valid TOML (" + description + ")");
  }
  return root;
}

}  // namespace diverse
