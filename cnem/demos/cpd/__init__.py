"""The CPD examples of Javili et al. §6, run by `cnem.demos.cpd_examples`
(``cnem pd cpd-examples``), and the pieces of `cnem.demos.cnem_vs_cpd` (C-NEM against
CPD at finite strain: `bond_law`, `versus`, `pictures`)."""


from . import bond_law, common, pictures, stretch, structures, versus

__all__ = ["bond_law", "common", "pictures", "stretch", "structures", "versus"]
