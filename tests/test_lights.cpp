// Light transport of the physical reference (render/reference/light_sampling.h,
// environment_light.h, reference_shading.cpp): lights with size rendered by
// light sampling, BSDF sampling and MIS against analytic irradiance; the
// environment map's sampling density; the first-hit option for unshadowed
// lights; the skin BRDF's energy conservation (render/view/view.h).
#include "test_support.h"

#include "core/errors.h"
#include "render/image/image_io.h"
#include "render/reference/environment_light.h"
#include "render/reference/light_sampling.h"
#include "render/reference/reference.h"
#include "sim/strands/synthetic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

using namespace hp;

namespace {

constexpr double kPi = M_PI;

/// A white Lambertian square (albedo 1, no wrap, no sheen) in the plane z = 0,
/// facing +z, seen straight down from (0, 0, 2) through a 0.2° field of view:
/// every pixel sees the plane within 4 mm of the origin.
struct PlaneShot {
    TriangleMesh plane;
    View view;
};

PlaneShot planeShot() {
    PlaneShot s;
    const float e = 5.f;
    s.plane.positions = {{-e, -e, 0.f}, {e, -e, 0.f}, {e, e, 0.f}, {-e, e, 0.f}};
    s.plane.triangles = {{0, 1, 2}, {0, 2, 3}};
    s.plane.computeNormals();
    View& v = s.view;
    v.camera.position = Vec3f(0.f, 0.f, 2.f);
    v.camera.target = Vec3f::Zero();
    v.camera.up = Vec3f(0.f, 1.f, 0.f);
    v.camera.fovY = 0.2f;
    v.camera.width = v.camera.height = 4;
    v.lights.clear();
    v.environment = Vec3f::Zero();
    v.head.color = Vec3f::Ones();
    v.head.wrap = 0.f;
    v.head.specular = 0.f;
    return s;
}

struct PixelStats {
    double mean = 0.0;
    double standardError = 0.0;  ///< of the mean over pixels
};

/// Renders the shot (physical, direct light only) and returns the red
/// channel's mean and its standard error over the pixels.
PixelStats renderPlane(const PlaneShot& shot, LightStrategy strategy, int spp, uint64_t seed = 1) {
    ReferenceSettings s;
    s.mode = ReferenceMode::Physical;
    s.samplesPerPixel = spp;
    s.bounces = 0;
    s.seed = seed;
    s.lightStrategy = strategy;
    ReferenceRenderer renderer;
    const Image img = renderer.render(shot.view, nullptr, &shot.plane, s);
    double sum = 0.0, sum2 = 0.0;
    const int n = img.width * img.height;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) sum += img.at(x, y, 0), sum2 += double(img.at(x, y, 0)) * img.at(x, y, 0);
    PixelStats st;
    st.mean = sum / n;
    const double var = std::max(0.0, sum2 / n - st.mean * st.mean) * n / (n - 1);
    st.standardError = std::sqrt(var / n);
    return st;
}

/// Each strategy's mean must be the analytic value within 4 standard errors
/// (plus 0.2% for the pixels' footprint and float error).
void expectAllStrategiesAgree(const PlaneShot& shot, double expected, const char* what) {
    for (LightStrategy strategy : {LightStrategy::Mis, LightStrategy::LightOnly, LightStrategy::BsdfOnly}) {
        const PixelStats st = renderPlane(shot, strategy, 256);
        const char* name = strategy == LightStrategy::Mis ? "MIS" : strategy == LightStrategy::LightOnly ? "light" : "BSDF";
        std::printf("%s, %s sampling: %.5f ± %.5f (analytic %.5f)\n", what, name, st.mean, st.standardError, expected);
        EXPECT_NEAR(st.mean, expected, 4.0 * st.standardError + 2e-3 * expected) << what << ", " << name << " sampling";
    }
}

/// Form factor from a point to a rectangle X × Y (in units of the height)
/// whose corner lies straight above it in a parallel plane (Howell, "A
/// Catalog of Radiation Heat Transfer Configuration Factors", C-11).
double cornerFormFactor(double X, double Y) {
    const double a = std::sqrt(1.0 + X * X), b = std::sqrt(1.0 + Y * Y);
    return (X / a * std::atan(Y / a) + Y / b * std::atan(X / b)) / (2.0 * kPi);
}

}  // namespace

TEST(Lights, DiskOnTheAxisMatchesPiLSinSquaredAlphaByEveryStrategy) {
    // A disk of radius R at height h facing the plane: E = π L sin²α with
    // sin²α = R²/(R² + h²); a white Lambertian plane reflects E/π.
    PlaneShot shot = planeShot();
    Light disk;
    disk.type = LightType::Disk;
    disk.position = Vec3f(0.f, 0.f, 0.5f);
    disk.direction = Vec3f(0.f, 0.f, -1.f);
    disk.size = Vec2f(0.6f, 0.6f);
    disk.intensity = 1.5f;
    shot.view.lights = {disk};
    const double R = 0.3, h = 0.5, L = 1.5 / (kPi * R * R);
    expectAllStrategiesAgree(shot, L * R * R / (R * R + h * h), "disk");

    // One-sided: turned away, it lights nothing.
    shot.view.lights[0].direction = Vec3f(0.f, 0.f, 1.f);
    EXPECT_EQ(renderPlane(shot, LightStrategy::Mis, 4).mean, 0.0);
}

TEST(Lights, QuadOnTheAxisMatchesItsFormFactorByEveryStrategy) {
    PlaneShot shot = planeShot();
    Light quad;
    quad.type = LightType::Quad;
    quad.position = Vec3f(0.f, 0.f, 0.4f);
    quad.direction = Vec3f(0.f, 0.f, -1.f);
    quad.size = Vec2f(0.8f, 0.3f);
    quad.intensity = 2.f;
    shot.view.lights = {quad};
    const double L = 2.0 / (0.8 * 0.3);
    const double F = 4.0 * cornerFormFactor(0.4 / 0.4, 0.15 / 0.4);
    expectAllStrategiesAgree(shot, L * F, "quad");
}

TEST(Lights, DistantLightWithAngleGivesItsIntensityAsIrradiance) {
    // A cone of half-angle θ fully above the horizon, its axis at 30° from the
    // normal: E = π L sin²θ cos 30°, and L was chosen so that π L sin²θ is
    // the intensity.
    PlaneShot shot = planeShot();
    Light sun;
    sun.type = LightType::Directional;
    sun.angle = 20.f;
    sun.intensity = 3.f;
    sun.direction = -Vec3f(std::sin(float(kPi) / 6.f), 0.f, std::cos(float(kPi) / 6.f));
    shot.view.lights = {sun};
    expectAllStrategiesAgree(shot, 3.0 * std::cos(kPi / 6.0) / kPi, "distant light with angle");
}

TEST(Lights, SampledDensitiesMatchTheHitDensities) {
    // For each shape, sample() and hit() must agree on the density of the
    // same direction (MIS weights rely on it) and on the radiance.
    Light quad;
    quad.type = LightType::Quad;
    quad.position = Vec3f(0.1f, 0.3f, 0.2f);
    quad.direction = Vec3f(0.2f, -1.f, -0.3f);
    quad.size = Vec2f(0.3f, 0.2f);
    Light disk = quad;
    disk.type = LightType::Disk;
    Light sun;
    sun.angle = 5.f;
    sun.direction = Vec3f(0.3f, -1.f, 0.1f);
    const Vec3f p(0.f, 0.f, 0.f);
    for (const Light& l : {quad, disk, sun}) {
        const SampledLight light(l);
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        int valid = 0;
        for (int i = 0; i < 200; ++i) {
            const LightSample s = light.sample(p, Vec2f(uni(rng), uni(rng)));
            if (!s.valid) continue;
            ++valid;
            Vec3f le;
            float pdf = 0.f;
            ASSERT_TRUE(light.hit(p, s.wi, std::numeric_limits<float>::infinity(), &le, &pdf));
            EXPECT_NEAR(pdf, s.pdf, 1e-3f * s.pdf);
            EXPECT_TRUE(le.isApprox(s.radiance));
        }
        EXPECT_GT(valid, 150);
    }
}

// ------------------------------------------------------------ environment --

namespace {

EnvironmentMap randomMap(int w, int h, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    auto rgb = std::make_shared<std::vector<float>>(size_t(w) * h * 3);
    for (float& v : *rgb) v = uni(rng) * uni(rng) * 4.f;
    EnvironmentMap m;
    m.width = w;
    m.height = h;
    m.rgb = rgb;
    m.rotationDegrees = 37.f;
    return m;
}

float luminance(const Vec3f& c) { return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z(); }

}  // namespace

TEST(EnvironmentLight, PdfIntegratesToOneOverTheSphere) {
    const EnvironmentLight env(Vec3f::Zero(), randomMap(24, 12, 5));
    ASSERT_TRUE(env.active());
    // Midpoint rule in (θ, φ), fine against the map's pixels.
    const int nt = 720, np = 1440;
    double sum = 0.0;
    for (int j = 0; j < nt; ++j) {
        const double theta = kPi * (j + 0.5) / nt;
        for (int i = 0; i < np; ++i) {
            const double phi = 2.0 * kPi * (i + 0.5) / np;
            const Vec3f d(float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)), float(std::sin(theta) * std::sin(phi)));
            sum += env.pdf(d) * std::sin(theta) * (kPi / nt) * (2.0 * kPi / np);
        }
    }
    EXPECT_NEAR(sum, 1.0, 2e-3);
}

TEST(EnvironmentLight, PdfIsProportionalToLuminanceTimesSinTheta) {
    // At each pixel's centre (turned by the map's rotation), pdf · sin θ must
    // be the same multiple of luminance · sin θ_pixel for every pixel:
    // p(ω) = p(u, v) / (2π² sin θ) with p(u, v) ∝ luminance · sin θ_pixel.
    const EnvironmentMap map = randomMap(16, 8, 9);
    const EnvironmentLight env(Vec3f::Zero(), map);
    const float rot = map.rotationDegrees * float(kPi) / 180.f;
    double ratio0 = -1.0;
    for (int j = 0; j < map.height; ++j) {
        for (int i = 0; i < map.width; ++i) {
            const float u = (float(i) + 0.5f) / float(map.width), v = (float(j) + 0.5f) / float(map.height);
            const Vec3f r = latLongDirection(u, v);
            const Vec3f d(std::cos(rot) * r.x() + std::sin(rot) * r.z(), r.y(), -std::sin(rot) * r.x() + std::cos(rot) * r.z());
            const float* px = &(*map.rgb)[(size_t(j) * map.width + i) * 3];
            const Vec3f L(px[0], px[1], px[2]);
            EXPECT_TRUE(env.radiance(d).isApprox(L, 1e-5f)) << i << ", " << j;
            // The density over the map's (u, v): p(ω) · 2π² sin θ.
            const double sinT = std::sin(kPi * v);
            const double pUv = env.pdf(d) * 2.0 * kPi * kPi * sinT;
            const double ratio = pUv / (luminance(L) * sinT);
            if (ratio0 < 0.0) ratio0 = ratio;
            EXPECT_NEAR(ratio, ratio0, 1e-4 * ratio0) << i << ", " << j;
        }
    }
    // And sample() draws directions with the density pdf() reports (away
    // from pixel edges, where float rounding may pick the neighbour).
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    int compared = 0;
    for (int k = 0; k < 500; ++k) {
        const LightSample s = env.sample(Vec2f(uni(rng), uni(rng)));
        ASSERT_TRUE(s.valid);
        const Vec3f d = s.wi;
        const Vec2f uv = latLongCoordinates(
            Vec3f(std::cos(rot) * d.x() - std::sin(rot) * d.z(), d.y(), std::sin(rot) * d.x() + std::cos(rot) * d.z()));
        const float fu = uv.x() * float(map.width) - std::floor(uv.x() * float(map.width));
        const float fv = uv.y() * float(map.height) - std::floor(uv.y() * float(map.height));
        if (std::min({fu, fv, 1.f - fu, 1.f - fv}) < 1e-3f) continue;
        ++compared;
        EXPECT_NEAR(env.pdf(d), s.pdf, 2e-3f * s.pdf);
        EXPECT_TRUE(env.radiance(d).isApprox(s.radiance, 1e-5f));
    }
    EXPECT_GT(compared, 480);
}

TEST(EnvironmentLight, ConstantMapRendersLikeTheConstantEnvironment) {
    // A white Lambertian plane under a uniform sky c receives E = π c from its
    // upper hemisphere and reflects E/π = c. Both the constant colour and a
    // map that holds it (turned, which must not matter) must give c.
    PlaneShot shot = planeShot();
    const Vec3f c(0.4f, 0.4f, 0.4f);
    shot.view.environment = c;
    const PixelStats constant = renderPlane(shot, LightStrategy::Mis, 256);
    shot.view.environment = Vec3f::Zero();
    EnvironmentMap map;
    map.width = 8;
    map.height = 4;
    map.rgb = std::make_shared<std::vector<float>>(size_t(8 * 4 * 3), 0.4f);
    map.rotationDegrees = 80.f;
    shot.view.environmentMap = map;
    const PixelStats mapped = renderPlane(shot, LightStrategy::Mis, 256);
    std::printf("constant %.5f ± %.5f, map %.5f ± %.5f, analytic 0.4\n", constant.mean, constant.standardError,
                mapped.mean, mapped.standardError);
    EXPECT_NEAR(constant.mean, 0.4, 4.0 * constant.standardError + 1e-3);
    EXPECT_NEAR(mapped.mean, 0.4, 4.0 * mapped.standardError + 1e-3);
}

TEST(EnvironmentLight, LoadsAnExrAndNamesABrokenFile) {
    const test::TempDir dir;
    const std::string path = (dir.path() / "sky.exr").string();
    Image img(4, 2, {"R", "G", "B"});
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y, c) = y == 0 ? 2.f : 0.5f;
    ImageWriteOptions opt;
    opt.halfFloat = false;
    writeImage(path, img, opt);
    const EnvironmentMap m = loadEnvironmentMap(path, 2.f, 0.f);
    ASSERT_EQ(m.width, 4);
    ASSERT_EQ(m.height, 2);
    // Both rows cover the same solid angle: mean = 2 × (2 + 0.5)/2.
    EXPECT_NEAR(m.mean.x(), 2.5f, 1e-5f);
    const std::string missing = (dir.path() / "nope.exr").string();
    try {
        loadEnvironmentMap(missing, 1.f, 0.f);
        FAIL() << "no error for a missing map";
    } catch (const AssetError& e) {
        EXPECT_NE(std::string(e.what()).find("nope.exr"), std::string::npos) << e.what();
    }
}

// --------------------------------------------------------- first-hit lights --

namespace {

/// `strands` synthetic strands on a 0.1 m sphere head, seen from
/// (0, 0.05, 0.9), lit only by one directional light from (−1, −1, −1)
/// marked unshadowed, black environment.
struct HairUnderOneLight {
    StrandFrame strands;
    TriangleMesh head;
    View view;
};

HairUnderOneLight hairUnderOneUnshadowedLight(size_t strands, int width, int height) {
    SyntheticHairSettings hs;
    hs.strands = strands;
    HairUnderOneLight h{makeSyntheticHair(hs), makeSphereMesh(Vec3f::Zero(), 0.1f, 16, 32), View{}};
    h.view.camera.position = Vec3f(0.f, 0.05f, 0.9f);
    h.view.camera.width = width;
    h.view.camera.height = height;
    h.view.environment = Vec3f::Zero();
    h.view.lights = {Light{}};
    h.view.lights[0].direction = Vec3f(-1.f, -1.f, -1.f);
    h.view.lights[0].castsShadows = false;
    return h;
}

}  // namespace

TEST(Lights, FirstHitLightsNeverContributeAfterABounce) {
    // Hair on a head, lit only by a light marked unshadowed. With first-hit,
    // a path with bounces must give exactly the picture of direct light alone
    // and unshadowed (nothing after the first hit), while the shadowed default
    // shows that this scene does have light after a bounce.
    const HairUnderOneLight shot = hairUnderOneUnshadowedLight(3000, 48, 32);
    const StrandFrame& strands = shot.strands;
    const TriangleMesh& head = shot.head;
    View view = shot.view;
    view.head.color = Vec3f::Ones();
    ReferenceSettings s;
    s.mode = ReferenceMode::Physical;
    s.samplesPerPixel = 16;
    s.shadowRouletteThreshold = 0.f;
    s.fiber.sigmaA = Vec3f::Zero();  // white hair: much light after a bounce
    ReferenceRenderer renderer;
    auto sum = [](const Image& img) {
        double t = 0.0;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) t += img.at(x, y, 0);
        return t;
    };

    s.unshadowedLights = UnshadowedLights::FirstHit;
    s.bounces = 4;
    const Image firstHit = renderer.render(view, &strands, &head, s);
    ReferenceSettings direct = s;
    direct.unshadowedLights = UnshadowedLights::Shadowed;
    direct.shadows = false;
    direct.bounces = 0;
    const Image unshadowedDirect = renderer.render(view, &strands, &head, direct);
    ASSERT_GT(sum(firstHit), 0.0);
    for (size_t i = 0; i < firstHit.pixels.size(); ++i)
        ASSERT_EQ(firstHit.pixels[i], unshadowedDirect.pixels[i]) << "value " << i;

    ReferenceSettings shadowed = s;
    shadowed.unshadowedLights = UnshadowedLights::Shadowed;
    shadowed.shadows = false;
    const Image withBounces = renderer.render(view, &strands, &head, shadowed);
    std::printf("first-hit %.3f, with bounces %.3f\n", sum(firstHit), sum(withBounces));
    // White hair passes much light on after a bounce: 15-30 % more at 4-16
    // spp (the estimate is noisy); 10 % tells the two modes apart.
    EXPECT_GT(sum(withBounces), 1.1 * sum(firstHit));
}

// ------------------------------------------------------------------- skin --

TEST(Skin, ReflectsAtMostWhatItReceivesAndTheAlbedoWhenDiffuse) {
    // ∫ skinShade(l) dω_l over the sphere (cosine included) is the fraction
    // of uniform incident light reflected toward v: the albedo exactly for the
    // wrapped Lambert (any wrap), never above 1 with the sheen.
    auto reflected = [](const SurfaceMaterial& m, const Vec3f& v) {
        const int nt = 400, np = 400;
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        const Vec3f n = Vec3f::UnitZ();
        for (int j = 0; j < nt; ++j) {
            const double ct = -1.0 + 2.0 * (j + 0.5) / nt;  // uniform in cos θ: dω = dcos dφ
            const double st = std::sqrt(1.0 - ct * ct);
            for (int i = 0; i < np; ++i) {
                const double phi = 2.0 * kPi * (i + 0.5) / np;
                const Vec3f l(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct));
                sum += skinShade(m, n, l, v).cast<double>() * (2.0 / nt) * (2.0 * kPi / np);
            }
        }
        return Vec3f(sum.cast<float>());
    };
    SurfaceMaterial m;
    m.color = Vec3f(0.9f, 0.6f, 0.3f);
    for (float wrap : {0.f, 0.2f, 0.6f}) {
        m.wrap = wrap;
        m.specular = 0.f;
        const Vec3f r = reflected(m, Vec3f(0.3f, 0.f, 0.95f).normalized());
        EXPECT_TRUE(r.isApprox(m.color, 5e-3f)) << "wrap " << wrap << ": " << r.transpose();
    }
    m.color = Vec3f::Ones();
    for (float ks : {0.04f, 0.5f, 1.f}) {
        for (float shininess : {1.f, 30.f, 200.f}) {
            for (float thetaV : {0.f, 45.f, 80.f}) {
                m.specular = ks;
                m.shininess = shininess;
                m.wrap = 0.2f;
                const float t = thetaV * float(kPi) / 180.f;
                const Vec3f r = reflected(m, Vec3f(std::sin(t), 0.f, std::cos(t)));
                EXPECT_LE(r.maxCoeff(), 1.005f) << "ks " << ks << " s " << shininess << " view " << thetaV;
            }
        }
    }
}

TEST(Lights, ShadowRouletteOnlyWhereAShadowRayIsTraced) {
    // Shadow-ray roulette (ReferenceSettings::shadowRouletteThreshold) trades
    // noise for skipped shadow rays; a light sample that traces no shadow
    // ray (a first-hit light, or shadows off) must not pay that noise: its
    // image may not depend on the threshold. With shadow rays it does.
    const HairUnderOneLight shot = hairUnderOneUnshadowedLight(600, 40, 30);
    const StrandFrame& strands = shot.strands;
    const TriangleMesh& head = shot.head;
    View view = shot.view;
    ReferenceSettings s;
    s.mode = ReferenceMode::Physical;
    s.samplesPerPixel = 4;
    s.bounces = 1;
    ReferenceRenderer renderer;
    auto differs = [&](ReferenceSettings a) {
        a.shadowRouletteThreshold = 0.f;
        const Image exact = renderer.render(view, &strands, &head, a);
        a.shadowRouletteThreshold = 10.f;
        const Image roulette = renderer.render(view, &strands, &head, a);
        return exact.pixels != roulette.pixels;
    };
    s.unshadowedLights = UnshadowedLights::FirstHit;
    EXPECT_FALSE(differs(s)) << "first-hit light";
    s.unshadowedLights = UnshadowedLights::Shadowed;
    s.shadows = false;
    EXPECT_FALSE(differs(s)) << "shadows off";
    s.shadows = true;
    EXPECT_TRUE(differs(s)) << "shadowed light";
}

TEST(Lights, HeadCastsNoShadowOnItselfForAnyStrategy) {
    // The head casts no shadow on itself (RayStart::throughHead): a part of
    // the head between a head point and a light must be ignored alike by the
    // light samples' shadow rays and by the BSDF rays' search for the light,
    // or light, BSDF and MIS estimates would disagree. A second head square
    // hangs between the plane and the disk, covering most of it.
    PlaneShot shot = planeShot();
    const uint32_t base = uint32_t(shot.plane.positions.size());
    const float e = 0.25f, z = 0.25f;
    for (const Vec3f& c : {Vec3f(-e, -e, z), Vec3f(e, -e, z), Vec3f(e, e, z), Vec3f(-e, e, z)}) shot.plane.positions.push_back(c);
    shot.plane.triangles.push_back({base, base + 1, base + 2});
    shot.plane.triangles.push_back({base, base + 2, base + 3});
    shot.plane.computeNormals();
    shot.view.camera.position = Vec3f(0.f, 0.f, 0.1f);  // under the occluder, looking down at the plane
    shot.view.camera.target = Vec3f::Zero();
    Light disk;
    disk.type = LightType::Disk;
    disk.position = Vec3f(0.f, 0.f, 0.5f);
    disk.direction = Vec3f(0.f, 0.f, -1.f);
    disk.size = Vec2f(0.6f, 0.6f);
    disk.intensity = 1.5f;
    shot.view.lights = {disk};
    const double R = 0.3, h = 0.5, L = 1.5 / (kPi * R * R);
    expectAllStrategiesAgree(shot, L * R * R / (R * R + h * h), "disk over a head that covers it");
}
