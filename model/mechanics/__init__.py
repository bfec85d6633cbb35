"""Mechanics: the parameter set, the DOFs, the elements and the assembled linearized bogie.

Holds the parameter set and its TOML format (:mod:`.parameters`), the one DOF naming scheme
(:mod:`.dofs`), the elements (beam, rigid bodies, spring–damper connections), the assembly of
M, B, K (:mod:`.assembly`), the operating point's creep and motor terms (:mod:`.operating_point`),
the output quantities (torques, forces) as rows over the DOFs (:mod:`.outputs`) and the
excitation orders of the drive with the motor's pole pairs and the pinion's teeth
(:mod:`.excitation`).  May use :mod:`model.contact`; never the analyses, the studies or ``app``.
"""
