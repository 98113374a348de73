// JSON text to a value: syntax errors at line and column, duplicate keys, nesting depth; failures.
#include <algorithm>
#include <set>

#include "core/error.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

namespace {

// 1-based line and column of the byte before `byte` (nlohmann reports bytes read so far).
std::string line_col(const std::string& text, std::size_t byte) {
  const std::size_t idx = std::min(byte > 0 ? byte - 1 : 0, text.size());
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < idx; ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

}  // namespace

void Loader::fail(const std::string& path, const std::string& problem) const {
  throw InputError(clip(source_, 200) + ": " + (path.empty() ? "/" : path) + ": " + problem);
}

void Loader::fail(const std::string& path, const std::string& problem, const Json& got) const {
  fail(path, problem + " (got " + show(got) + ")");
}

Json Loader::parse(const std::string& text) const {
  // Track the path of the value being parsed so duplicate keys (which nlohmann would silently
  // collapse to the last one) can be reported with their JSON path.
  struct Frame {
    explicit Frame(bool is_array) : array(is_array) {}
    bool array;
    std::size_t index = 0;
    std::string key;
    std::set<std::string> keys;
  };
  std::vector<Frame> stack;
  const auto path_of_stack = [&] {
    std::string path;
    for (std::size_t i = 0; i + 1 < stack.size(); ++i)
      path = stack[i].array ? at(path, stack[i].index) : at(path, stack[i].key);
    return clip(path, 200);
  };
  const Json::parser_callback_t cb = [&](int depth, nlohmann::json::parse_event_t ev,
                                         Json& parsed) {
    using E = nlohmann::json::parse_event_t;
    // Deep nesting would make printing and freeing the value recurse past the stack.
    if ((ev == E::object_start || ev == E::array_start) && depth >= kMaxNesting)
      fail(path_of_stack(), "values are nested more than " + std::to_string(kMaxNesting) +
                                " levels deep; a scene needs far fewer");
    auto next_element = [&] {
      if (!stack.empty() && stack.back().array) ++stack.back().index;
    };
    switch (ev) {
      case E::object_start:
        stack.emplace_back(false);
        break;
      case E::array_start:
        stack.emplace_back(true);
        break;
      case E::key: {
        const std::string k = parsed.get<std::string>();
        Frame& f = stack.back();
        if (!f.keys.insert(k).second)
          fail(at(path_of_stack(), k), "duplicate key '" + clip(k) + "'");
        f.key = k;
        break;
      }
      case E::object_end:
      case E::array_end:
        stack.pop_back();
        next_element();
        break;
      case E::value:
        next_element();
        break;
    }
    return true;
  };
  try {
    return Json::parse(text, cb, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::parse_error& e) {
    const std::string what = e.what();
    const std::size_t k = what.find(": ", what.find("parse error"));
    const std::string msg = k == std::string::npos ? what : what.substr(k + 2);
    throw InputError(clip(source_, 200) + ": " + line_col(text, e.byte) + ": " + clip(msg, 200));
  } catch (const nlohmann::json::exception& e) {
    // e.g. "number overflow parsing '1e999'": locate the quoted token to give a position.
    std::string what = e.what();
    if (const std::size_t k = what.find("] "); k != std::string::npos) what = what.substr(k + 2);
    std::string where;
    const std::size_t q0 = what.find('\''), q1 = what.rfind('\'');
    if (q0 != std::string::npos && q1 > q0 + 1) {
      const std::size_t pos = text.find(what.substr(q0 + 1, q1 - q0 - 1));
      if (pos != std::string::npos) where = line_col(text, pos + 1) + ": ";
    }
    throw InputError(clip(source_, 200) + ": " + where + clip(what, 200));
  }
}

}  // namespace femto::scene_json
