// The contact benchmarks; each prints one table to stdout.
#pragma once

namespace fahr::contact::bench {

int run_punch();       // flat punch vs Boussinesq at 50, 200, 1000 Hz FEM
int run_overshoot();   // Figure 7: force-aware vs penalty past the device limit
int run_smoothness();  // 50 Hz line of the force: compliance solve vs naive loop
// Random lockstep runs checked for NaN, force over the limit and persistent
// penetration; options after the command name (property.cpp).
int run_property(int argc, char** argv);

}  // namespace fahr::contact::bench
