"""Arbitrary Lagrangian-Eulerian mesh motion of the plane-strain engine: the rezoning passes
(:mod:`.rezone`), their host-side stencils (:mod:`.stencils`), the donor-cell remap
(:mod:`.remap`) and the tool-frame mesh that travels with the tool (:mod:`.toolframe`)."""
