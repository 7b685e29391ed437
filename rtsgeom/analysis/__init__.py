"""Setup analyses on top of the pipeline: mounting tolerance, near field, cable ghosts, arc design."""
