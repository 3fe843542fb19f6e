"""grasptwist: resolve an object twist into finger-tip twists of a three-fingered grasp."""
