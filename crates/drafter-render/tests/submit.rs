//! `Renderer::submit_frame` (the browser page's frames: the surfaces submitted before the
//! silhouettes are found, the lines after) draws the same pixels as `Renderer::encode_frame`
//! (one command buffer), in every kind of frame: lines, edges, a shadow, a drag's reduced frame.

mod common;

use drafter_render::{Enhancements, RenderOptions, Renderer, ShadowMode, Style};

/// The output texture's bytes after the frame just submitted.
fn output_bytes(renderer: &Renderer) -> Vec<u8> {
    let gpu = renderer.gpu();
    let texture = renderer.output_texture().expect("a frame was drawn");
    let (w, h) = (texture.width(), texture.height());
    let row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test readback"),
        size: u64::from(row * h),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(h) },
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([encoder.finish()]);
    buffer.slice(..).map_async(wgpu::MapMode::Read, |result| result.expect("readback maps"));
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).expect("the GPU finishes");
    buffer.get_mapped_range(..).expect("the readback is mapped").to_vec()
}

#[test]
fn submitted_frames_are_the_encoded_frames() {
    let mut renderer: Renderer = common::renderer();
    renderer.set_model(&common::sample()).expect("the sample uploads");
    let base = RenderOptions { style: Style::Gradient, supersample: 1, size: (96, 72), ..Default::default() };
    let cases = [
        ("plain", base.clone()),
        ("lines and edges", RenderOptions { lines: true, enhancements: Enhancements::ALL, ..base.clone() }),
        (
            "soft shadow, gooch",
            RenderOptions { lines: true, shadow: ShadowMode::Soft, style: Style::Gooch, ..base.clone() },
        ),
        ("a drag's frame", RenderOptions { lines: true, interactive: true, ..base.clone() }),
    ];
    for (name, options) in cases {
        let device = renderer.gpu().device.clone();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let encoded_info = renderer.encode_frame(&options, &mut encoder, None).expect("the frame encodes");
        renderer.gpu().queue.submit([encoder.finish()]);
        let encoded = output_bytes(&renderer);
        let encoded_silhouettes = renderer.last_silhouettes().map(|s| s.segments.len());
        let submitted_info = renderer.submit_frame(&options, None).expect("the frame submits");
        let submitted = output_bytes(&renderer);
        assert_eq!(submitted_info.camera.view_from_render, encoded_info.camera.view_from_render, "{name}");
        assert_eq!(renderer.last_silhouettes().map(|s| s.segments.len()), encoded_silhouettes, "{name}");
        assert!(encoded.iter().any(|&b| b != 0), "{name}: the frame is empty");
        assert!(encoded == submitted, "{name}: the submitted frame differs from the encoded one");
    }
}
