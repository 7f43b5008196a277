"""Work-precision study (same as `bearing-lab bench`): writes reports/performance/."""
import sys

from bearing_lab.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
