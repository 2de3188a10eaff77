"""`python3 -m chainsim fit ARGS...`: the Python half of `chainsim fit` (cases/cli/fit_command.cpp runs it so;
python/chainsim/fitting.py, docs/fit.md)."""
import sys

if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] != "fit":
        sys.stderr.write("usage: python3 -m chainsim fit TARGET DATA.csv... [options] (see 'chainsim fit --help')\n")
        sys.exit(2)
    from chainsim.fitting import main
    sys.exit(main(sys.argv[2:]))
