// Stress: rigid transform, triangulation, plane fit, intersections
