// Evaluates a registry law through the installed headers and libraries and checks it against
// the closed form T(t) = (1 + mu t / alpha)^-alpha (Jarabo et al. 2018); exit 0 when they agree.
#include <cmath>
#include <cstdio>

#include "weft/transmittance/registry.h"

int main() {
  const auto law = weft::transmittance::make_law({"gamma", {{"alpha", 0.5}, {"mean_extinction", 2.0}}, ""});
  int bad = 0;
  for (const double t : {0.0, 0.25, 1.0, 10.0}) {
    const double expected = std::pow(1.0 + 2.0 * t / 0.5, -0.5);
    const double got = law->transmittance(t);
    std::printf("T(%g) = %.17g (closed form %.17g)\n", t, got, expected);
    if (!(std::abs(got - expected) <= 1e-14 * expected)) ++bad;
  }
  return bad == 0 ? 0 : 1;
}
