"""The FE cutting models built on the engine: orthogonal cutting (:mod:`.orthogonal`), its
validation against measured forces (:mod:`.validate`, its stored record
:mod:`.validation_record`) and results (:mod:`.output`), the 3D
boring model (:mod:`.boring3d`) and the 3D slab cross-check against the 2D engine
(:mod:`.slab3d`)."""
