"""The CPD examples of Javili et al. §6, run by `demos/cpd_examples.py` (``cnem pd cpd``)."""
