#pragma once
// Routing a stage's output into downstream queues. A stage returns a value, an optional or a
// vector; `into(queue)` makes the emit function that pushes each of them, in order.

#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

namespace dynavins::pipeline {

template <typename T> struct is_optional : std::false_type {};
template <typename T> struct is_optional<std::optional<T>> : std::true_type {};
template <typename T> struct is_vector : std::false_type {};
template <typename T, typename A> struct is_vector<std::vector<T, A>> : std::true_type {};

/// Pushes `out` (a value, optional or vector of values) into `target` (a queue or fan-in producer).
template <typename Target, typename T>
void push_all(Target& target, T&& out) {
  using U = std::decay_t<T>;
  if constexpr (is_optional<U>::value) {
    if (out) target.push(std::move(*out));
  } else if constexpr (is_vector<U>::value) {
    for (auto& x : out) target.push(std::move(x));
  } else {
    target.push(std::forward<T>(out));
  }
}

/// Emit function for a stage whose output goes to one queue.
template <typename Target>
auto into(Target& target) {
  return [&target](auto&& out) { push_all(target, std::forward<decltype(out)>(out)); };
}

/// Emit function for a stage that produces nothing (a sink): process() returns void.
struct NoOutput {
  template <typename T>
  void operator()(T&&) const {}
};

}  // namespace dynavins::pipeline
