"""install.consumer: the installed Python module imports from the prefix alone and evaluates a law."""
import os
import sys

import weft

prefix = os.path.realpath(sys.argv[1])
assert os.path.realpath(weft.__file__).startswith(prefix), weft.__file__
T = weft.law("gamma", alpha=0.5, mean_extinction=2.0).T(1.0)
assert abs(T - 5 ** -0.5) < 1e-15, T  # (1 + 2/0.5)^-0.5
print("installed weft module:", weft.__file__, "T(1) =", T)
