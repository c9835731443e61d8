"""Configuration of the FE models: the solver keys both share (:mod:`.solver`), the
orthogonal-cutting schema (:mod:`.orthogonal`), the 3D boring schema (:mod:`.boring3d`), the
``[contact]`` section both use (:mod:`.contact`), the typed ``[mesh] frame`` (:mod:`.frame`),
the model spec (:mod:`.spec`, built by :mod:`.spec_build`) and the settings both write into
an engine's parameter vector (:mod:`.engine_settings`)."""
