#pragma once
// std::visit with a set of lambdas: std::visit(Overloaded{[](const Sphere&) {...}, ...}, shape).

namespace aloft::internal {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

}  // namespace aloft::internal
