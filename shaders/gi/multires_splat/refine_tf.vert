#version 450 core
// Transform-feedback refinement (000 §3 step 5 as published): one point per list item.
layout(location = 0) in uvec2 aItem;
flat out uvec2 vItem;
void main() {
    vItem = aItem;
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
