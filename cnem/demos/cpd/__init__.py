"""The CPD examples of Javili et al. §6, run by `cnem.demos.cpd_examples`
(``cnem pd cpd-examples``)."""


from . import common, stretch, structures

__all__ = ["common", "stretch", "structures"]
