// A user's program on the installed library: renders a scene given as text into memory and counts its hits.
#include <algray/algray.h>

#include <cmath>
#include <cstdio>
#include <exception>

int main() {
  try {
    algray::api::Scene scene = algray::api::Scene::from_toml(
        "[surface]\nequation = \"x^2+y^2+z^2-1\"\n[extent]\nradius = 2\n"
        "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov_y = 45\n",
        "ball.toml");
    scene.set("image.width", "24").set("image.height", "16");
    algray::api::Renderer renderer;
    const algray::api::Image image = renderer.render(scene, {.preview = true});
    int hits = 0;
    for (float z : image.depth()) hits += std::isfinite(z);
    std::printf("%s on %s: %dx%d, %d pixels hit\n", algray::api::version().c_str(),
                renderer.device().name.c_str(), image.width(), image.height(), hits);
    return hits > 0 && hits < image.width() * image.height() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "algray_consumer: %s\n", e.what());
    return 1;
  }
}
