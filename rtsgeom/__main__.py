import sys

try:
    from .cli import console
except KeyboardInterrupt:  # Ctrl-C while the libraries load: nothing written yet
    print("rtsgeom: interrupted", file=sys.stderr)
    sys.exit(130)

console()
