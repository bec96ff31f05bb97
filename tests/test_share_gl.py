"""A Session's output handed to OpenGL without a copy (``Session(share="gl")``, ``frame.gl()``;
cltess/backends/opencl/share_gl.py; issue 15): without a current GL context the Session is
refused with the reason.  The hand-over itself is tested with Vulkan's in test_share_handover.py
(on an NVIDIA device with EGL and Vulkan)."""

import pytest

import cltess
from cltess.backends.opencl.share_cuda import SharingUnavailable


def test_without_a_current_gl_context_a_session_refuses_to_share_with_gl(tessellator, tea_table):
    with pytest.raises(SharingUnavailable, match="OpenGL context current"):
        cltess.Session(tea_table, tessellator=tessellator, pixels=0.5, share="gl")
