"""The text pose syntax of the Python client (deform_client.poses), checked without a server: the
axis and the angle read from the right, quoted names, and malformed terms."""

import unittest

from deform_client.poses import parse_pose_spec


class PoseSpecTest(unittest.TestCase):
    def test_names_with_colons_commas_and_spaces(self):
        angles = parse_pose_spec(
            'mixamorig:LeftForeArm:z:60, "left arm, upper" : x : -5, a:b:c:x:1, "q:r":y:2')
        self.assertEqual([(a.joint, a.axis, a.degrees) for a in angles],
                         [("mixamorig:LeftForeArm", "z", 60.0), ("left arm, upper", "x", -5.0),
                          ("a:b:c", "x", 1.0), ("q:r", "y", 2.0)])

    def test_plain_terms_and_rest(self):
        angles = parse_pose_spec(" knee : flexion : 90 ,0:x:-10.5")
        self.assertEqual([(a.joint, a.axis, a.degrees) for a in angles],
                         [("knee", "flexion", 90.0), ("0", "x", -10.5)])
        self.assertEqual(parse_pose_spec("  rest "), [])

    def test_malformed_terms_are_refused(self):
        for bad in ("knee:flexion", ":x:10", "knee::10", "knee:x:", "knee:x:abc", "knee:x:nan",
                    'knee:x:10,,', '"a"x:10', '"a":b:x:10', '"left arm:x:10'):
            with self.assertRaises(ValueError, msg=bad):
                parse_pose_spec(bad)


if __name__ == "__main__":
    unittest.main()
