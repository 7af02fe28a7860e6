pub mod grasps;
