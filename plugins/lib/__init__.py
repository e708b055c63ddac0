"""The papers' mathematics and data shared by several rooms; nothing here registers a component.

``pose_distance`` (B&B eq. 1-3), ``root_frame`` (B&B §5.1), ``strokes`` (K&G §4.3 segmentation),
``guiding_stroke`` (K&G §3), ``hand_transition`` (K&G §3, §4.2), ``inverse_model`` (K&G §4.3), ``clip_repertoire``
(repertoires from labelled clips, from folders or in memory), the correspondence helpers (``body_size``,
``rest_posture``, ``travel``), ``velocity`` (Savitzky-Golay derivatives), ``compiled`` (numba where it is installed)
and ``rendering`` (off-screen pyvista scaffolding).
"""
