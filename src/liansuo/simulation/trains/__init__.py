"""Trains: consists, kinematics, drivers, automatic shunting and odometry."""
