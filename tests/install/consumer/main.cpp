// Uses the installed library: decodes sRGB 128 and checks it against the IEC formula.
#include <cmath>
#include <cstdio>

#include <matbake/color.hpp>
#include <matbake/version.hpp>

int main() {
  const float table = matbake::color::decode_table(matbake::color::Transfer::srgb, 8)[128];
  const double exact = std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4);
  std::printf("matbake %s: sRGB 128 -> %.9g (formula %.9g)\n", matbake::version, table, exact);
  return table == float(exact) ? 0 : 1;
}
