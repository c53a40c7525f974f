"""Retargeter: apply() over many poses == the C API's avm_retargeter_apply pose by pose."""

import os

import numpy as np
import pytest

import avatarmap as am
from avatarmap import _lib


@pytest.fixture(scope="module")
def poses(synth_file):
    return am.solve(am.read_landmarks(synth_file))


@pytest.mark.parametrize("avatar", ["vrm1_debug_robot.vrm", "vrm0_sphere.vrm"])
def test_apply_equals_per_pose_calls(data, poses, avatar):
    with am.Retargeter(os.path.join(data, "avatars", avatar)) as r:
        assert r.joint_count == len(r.joint_names) == len(r.joint_parents) > 0
        assert r.joint_parents[0] == -1 and all(r.joint_parents[1:] < np.arange(1, r.joint_count))
        hips = r.bone_joint("hips")
        assert hips >= 0 and r.bone_joint(0) == hips
        assert "humanoid" in r.binding or "VRM" in r.binding
        rot, trans = r.apply(poses)
        assert rot.shape == (len(poses), r.joint_count, 4) and trans.shape == (len(poses), 3)
        # The reference: one avm_retargeter_apply per pose, straight through ctypes.
        apply_one = _lib.fn("avm_retargeter_apply")
        rec = poses.records
        one_rot = np.empty((r.joint_count, 4), dtype=np.float32)
        one_trans = np.empty(3, dtype=np.float32)
        for i in range(len(poses)):
            assert apply_one(r._h, rec[i:i + 1].ctypes.data, one_rot.ctypes.data,
                             one_trans.ctypes.data) == 0
            np.testing.assert_array_equal(rot[i], one_rot)
            np.testing.assert_array_equal(trans[i], one_trans)
        assert np.allclose(np.linalg.norm(rot, axis=2), 1.0, atol=1e-5)
        # Foot locking keeps anchors between calls; a clip applied again from its start (a
        # time not after the previous pose's) starts afresh and gives the same rows.
        again = r.apply(poses[:4])
        np.testing.assert_array_equal(again[0][3], rot[3])
    assert r.closed
    with pytest.raises(am.InvalidArgumentError, match="closed"):
        r.apply(poses)


def test_mapping_errors(data):
    avatar = os.path.join(data, "avatars", "gltf_rigged_figure.glb")
    with pytest.raises(am.InvalidArgumentError, match="no_such_table"):
        am.Retargeter(avatar, mapping="no_such_table")
    with pytest.raises(am.AvatarmapError) as e:
        am.Retargeter(avatar)  # non-humanoid joint names: no table fits
    assert "gltf_rigged_figure.glb" in str(e.value)
