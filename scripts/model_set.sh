# Sourced by scripts/accuracy.sh, figures.sh and performance.sh: the model set they measure.
# The tables and figures of docs/ were measured on the reference implementation's models, which the
# repository does not carry: with SFFD_REFERENCE_DATA naming a copy (tests/data/README.md) the scripts
# reproduce them; without it the same runs use the repository's generated models and lattices.
if [ -n "${SFFD_REFERENCE_DATA:-}" ]; then
  D=$SFFD_REFERENCE_DATA/acaffd
  TEAPOT=t.bpt TEAPOT_L=t_control_points1.npy CUBE=cube2.obj CUBE_L=cube2_control_points5.npy
  SPHERE=sphere.obj SPHERE_L=sphere_control_points0.npy BIG=rabbit BIG_MESH=rabbit_cym.obj BIG_L=rabbit_cym_control_points0.npy
else
  D=tests/data
  TEAPOT=teapot.bpt TEAPOT_L=teapot_bend.npy CUBE=cube2.obj CUBE_L=cube2_twist.npy
  SPHERE=sphere.obj SPHERE_L=sphere_twist.npy BIG=torus BIG_MESH=torus.obj BIG_L=torus_twist.npy
fi
