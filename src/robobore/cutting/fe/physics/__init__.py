"""Scalar physics shared by the CPU and GPU engines: the tool's geometry, the contact law and the
tool support (:mod:`.tool_contact`), the heat passes of the plane-strain (:mod:`.thermal2d`)
and the hexahedral (:mod:`.thermal3d`) engines."""
